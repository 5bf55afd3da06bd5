"""Write RSL's canonical language (`rsl.syntax`) as a llama.cpp GBNF grammar for constrained sampling.

This is the only GBNF writer: the `nrtrans grammar` export, the decoding
automaton's grammar for OpenAI-compatible endpoints and the tests all use it.
Every program the grammar accepts also parses; value ranges, the workspace and
object knowledge stay the compiler's job, which is why the repair loop exists.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence

from rsl.profile import Profile
from rsl.syntax import (
    ARGUMENT_SEPARATOR,
    KEYWORD_GAP,
    LINE_END,
    MAX_FRACTION_DIGITS,
    MAX_IDENTIFIER,
    NO_PROGRAM,
    PROGRAM_END,
    TERMINATOR,
    Argument,
    NumberShape,
    ObjectShape,
    Syntax,
    syntax_of,
)

__all__ = ["MAX_FRACTION_DIGITS", "gbnf", "to_gbnf"]


def to_gbnf(profile: Profile, objects: Sequence[str] | None = None, *, keywords: Collection[str] | None = None,
            numbers: Mapping[str, Collection[str]] | None = None, max_statements: int | None = None,
            refusal: bool = False) -> str:
    """The grammar of `profile`, narrowed as `rsl.syntax.syntax_of` describes."""
    return gbnf(syntax_of(profile, keywords=keywords, objects=objects, numbers=numbers,
                          max_statements=max_statements, refusal=refusal))


def gbnf(syntax: Syntax) -> str:
    rules: dict[str, str] = {}
    names: dict[str, str] = {}  # rule body -> its name, so equal argument shapes share one rule
    alternatives = []
    for statement in syntax.statements:
        if not statement.args:
            alternatives.append(_literal(statement.keyword + TERMINATOR))
            continue
        parts = [_argument(arg, f"{statement.keyword}-{i}", rules, names) for i, arg in enumerate(statement.args)]
        alternatives.append(_literal(statement.keyword + KEYWORD_GAP) + " "
                            + f" {_literal(ARGUMENT_SEPARATOR)} ".join(parts) + " " + _literal(TERMINATOR))
    root = f"root ::= statement{{1,{syntax.max_statements}}} {_literal(PROGRAM_END)}"
    if syntax.refusal:
        root += f" | {_literal(NO_PROGRAM + LINE_END + PROGRAM_END)}"
    lines = [root, f"statement ::= ({' | '.join(alternatives)}) {_literal(LINE_END)}"]
    lines.extend(f"{name} ::= {body}" for name, body in rules.items())
    return "\n".join(lines) + "\n"


def _argument(arg: Argument, fallback: str, rules: dict[str, str], names: dict[str, str]) -> str:
    if isinstance(arg, ObjectShape):
        name = "object"  # one narrowing applies to every object argument
        body = (f"[a-zA-Z_] [a-zA-Z0-9_]{{0,{MAX_IDENTIFIER - 1}}}" if arg.names is None
                else " | ".join(_literal(n) for n in arg.names))
    elif arg.literals:
        name = f"number-{fallback}"
        body = " | ".join(_literal(n) for n in sorted(arg.literals))
    else:
        name = f"{'coordinate' if arg.signed else 'number'}-{arg.digits}"
        body = _number(arg)
    if body not in names:
        names[body] = name.replace("_", "-")
        rules[names[body]] = body
    return names[body]


def _number(shape: NumberShape) -> str:
    rest = f" [0-9]{{0,{shape.digits - 1}}}" if shape.digits > 1 else ""
    integer = f'("0" | [1-9]{rest})'
    return ('"-"? ' if shape.signed else "") + f'{integer} ("." [0-9]{{1,{MAX_FRACTION_DIGITS}}})?'


def _literal(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
