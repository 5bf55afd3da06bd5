"""One way to read a table of settings into a frozen dataclass, with errors in one style.

A section of settings is a dataclass whose fields say everything there is to
check: the type (from the annotation) and, in the field's metadata (`setting`),
the documentation, bounds and allowed values. `read_settings` rejects an
unknown key, a value of the wrong type or out of bounds with the same kind of
message everywhere: where (file and key), what was wrong, and what to do.
A robot profile's `[motion]`, `[limits]` and `[ros]` tables, the daemon's
config file and its `[speech.options]` table are read this way. It lives at the
bottom, beside the profile, so that everything above can use it.
"""

from __future__ import annotations

import dataclasses
import types
from collections.abc import Mapping
from typing import Any, TypeVar, Union, get_args, get_origin, get_type_hints

T = TypeVar("T")


def setting(default: Any = dataclasses.MISSING, *, doc: str, default_factory: Any = dataclasses.MISSING,
            min: float | None = None, max: float | None = None, above: float | None = None,
            choices: tuple[str, ...] = (), octal: bool = False, nonempty: bool = False,
            length: int | None = None) -> Any:
    """A dataclass field that is a setting; without a default it must be given.

    `min`/`max` bound a number (each number of a list) inclusively, `above` exclusively; `octal`
    wants a string of octal digits, `nonempty` a string or list that is not empty, `length` a list
    of that many items.
    """
    rules = {"min": min, "max": max, "above": above, "choices": choices or None, "octal": octal or None,
             "nonempty": nonempty or None, "length": length}
    metadata = {"doc": doc, **{k: v for k, v in rules.items() if v is not None}}
    if default_factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=default_factory, metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


def read_settings(cls: type[T], data: Any, *, error: type[Exception], source: str = "", prefix: str = "",
                  docs: str = "") -> T:
    """`cls` built from the table `data`; a nested dataclass field is read from a nested table, and a
    field typed `tuple[SomeDataclass, ...]` from a list of tables.

    `prefix` names the table in messages ("api."), `docs` where its settings are described.
    """
    where = f"{source}: " if source else ""
    if not isinstance(data, Mapping):
        raise error(f"{where}{prefix.rstrip('.') or 'the top level'} must be a table")
    hints = get_type_hints(cls)
    known = {f.name: f for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    unknown = sorted(set(data) - set(known))
    if unknown:
        also = f"; see {docs}" if docs else ""
        raise error(f"{where}unknown setting {prefix}{unknown[0]}\n"
                    f"  = help: the settings here are {', '.join(prefix + k for k in known)}{also}")
    missing = [name for name, f in known.items() if name not in data
               and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    if missing:
        raise error(f"{where}{prefix}{missing[0]} must be given: {known[missing[0]].metadata.get('doc', '')}")
    values: dict[str, Any] = {}
    for name, value in data.items():
        hint = hints[name]
        item = get_args(hint)[0] if get_origin(hint) is tuple else None
        if dataclasses.is_dataclass(hint):
            values[name] = read_settings(hint, value, error=error, source=source,  # type: ignore[arg-type]
                                         prefix=f"{prefix}{name}.", docs=docs)
        elif dataclasses.is_dataclass(item):
            if not isinstance(value, list):
                raise error(f"{where}{prefix}{name} must be a list of tables ([[{prefix}{name}]]), not {value!r}")
            values[name] = tuple(read_settings(item, entry, error=error, source=source,  # type: ignore[arg-type]
                                               prefix=f"{prefix}{name}[{index}].", docs=docs)
                                 for index, entry in enumerate(value, start=1))
        else:
            values[name] = check_value(f"{prefix}{name}", hint, value, known[name].metadata, error=error,
                                       source=source)
    return cls(**values)


def check_value(key: str, hint: Any, value: Any, rules: Mapping[str, Any], *, error: type[Exception],
                source: str = "") -> Any:
    """`value` converted to the setting's type (an int where a float goes is a float), or `error`."""
    where = f"{source}: " if source else ""

    def wrong(expected: str) -> Exception:
        return error(f"{where}{key} must be {expected}, not {value!r}")

    result = _typed(hint, value, wrong)
    if "length" in rules and len(result) != rules["length"]:
        raise error(f"{where}{key} must have {rules['length']} items, not {value!r}")
    for number in result if isinstance(result, tuple) else (result,):
        if not isinstance(number, int | float) or isinstance(number, bool):
            continue
        for rule, fails, says in (("min", lambda b, n=number: n < b, "below the minimum"),
                                  ("max", lambda b, n=number: n > b, "above the maximum"),
                                  ("above", lambda b, n=number: n <= b, "not above")):
            if rule in rules and fails(rules[rule]):
                raise error(f"{where}{key} = {value!r}" + (f": {number!r}" if number is not result else "")
                            + f" is {says} {rules[rule]}")
    if rules.get("nonempty") and not result:
        raise error(f"{where}{key} must not be empty")
    if rules.get("octal"):
        try:
            int(result, 8)
        except ValueError:
            raise wrong('an octal string like "0660"') from None
    choices = rules.get("choices")
    if choices and result not in choices:
        raise error(f"{where}{key} = {value!r} is not one of {', '.join(map(repr, choices))}")
    return result


def _typed(hint: Any, value: Any, wrong: Any) -> Any:
    options = get_args(hint) if get_origin(hint) in (Union, types.UnionType) else (hint,)
    for option in options:
        fits, converted = _convert(option, value)
        if fits:
            return converted
    raise wrong(_expected(options))


def _convert(option: Any, value: Any) -> tuple[bool, Any]:
    """Whether `value` is of the type `option`, and the value as that type."""
    if option is type(None) or option is bool or option is str:
        return isinstance(value, option), value
    if option is int:
        return isinstance(value, int) and not isinstance(value, bool), value
    if option is float:
        fits = isinstance(value, int | float) and not isinstance(value, bool)
        return fits, float(value) if fits else value
    if get_origin(option) is tuple:
        item = get_args(option)[0]
        fits = isinstance(value, list | tuple) and all(_convert(item, v)[0] for v in value)
        return fits, tuple(_convert(item, v)[1] for v in value) if fits else value
    if get_origin(option) is dict:
        return isinstance(value, Mapping), dict(value) if isinstance(value, Mapping) else value
    raise TypeError(f"a setting of type {option} cannot be read")


_NAMES = {bool: "true or false", int: "a whole number", float: "a number", str: "a string"}


def _expected(options: tuple[Any, ...]) -> str:
    names = []
    for option in options:
        if option is type(None):
            continue
        if get_origin(option) is tuple:
            names.append(f"a list of {_NAMES[get_args(option)[0]].removeprefix('a ')}s")
        elif get_origin(option) is dict:
            names.append("a table")
        else:
            names.append(_NAMES[option])
    return " or ".join(names)
