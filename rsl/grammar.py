"""Export the profile's RSL as a llama.cpp GBNF grammar for constrained sampling.

The grammar accepts exactly the canonical spelling the translator emits
(`Plan.to_rsl()`): one `keyword arg, arg;` per line, numbers as plain
decimals, and a final blank line. Ending on a blank line gives the model a
natural way to stop, since "\\n\\n" is a single token in most vocabularies
and the grammar must be able to accept it. Every program the grammar
accepts also parses; value ranges, the workspace and object knowledge stay
the compiler's job, which is why the repair loop exists.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from rsl.profile import IDENTIFIER, Param, Profile, Skill
from rsl.syntax import NO_PROGRAM

MAX_FRACTION_DIGITS = 4


def to_gbnf(profile: Profile, objects: Sequence[str] | None = None, *, refusal: bool = False) -> str:
    """The grammar; `objects` narrows object arguments to those names.

    With an empty `objects` list, skills that need an object are left out,
    since no valid statement could use them. With `refusal`, the single line
    `NO_PROGRAM` may stand in place of the statements.
    """
    if objects is not None:
        bad = [name for name in objects if not IDENTIFIER.match(name)]
        if bad:
            raise ValueError(f"object names must be C identifiers: {', '.join(map(repr, bad))}")
    skills = [s for s in profile.skills
              if objects or objects is None or all(p.kind != "object" for p in s.params)]
    rules: dict[str, str] = {}
    statement_rules = []
    for skill in skills:
        name = f"skill-{skill.keyword.replace('_', '-')}"
        rules[name] = _statement(skill, rules, profile)
        statement_rules.append(name)
    if any(p.kind == "object" for s in skills for p in s.params):
        rules["object"] = _object_rule(objects)
    lines = [
        f"root ::= statement{{1,{profile.max_statements}}} \"\\n\""
        + (f" | \"{NO_PROGRAM}\\n\\n\"" if refusal else ""),
        f"statement ::= ({' | '.join(statement_rules)}) \"\\n\"",
    ]
    lines.extend(f"{name} ::= {body}" for name, body in rules.items())
    return "\n".join(lines) + "\n"


def _statement(skill: Skill, rules: dict[str, str], profile: Profile) -> str:
    if not skill.params:
        return f'"{skill.keyword};"'
    parts = [_argument(p, rules, profile) for p in skill.params]
    return f'"{skill.keyword} " ' + ' ", " '.join(parts) + ' ";"'


def _argument(param: Param, rules: dict[str, str], profile: Profile) -> str:
    if param.kind == "object":
        return "object"
    high = param.max if param.max is not None else 99.0
    low = param.min if param.min is not None else 0.0
    magnitude = max(abs(high), abs(low))
    digits = max(1, len(str(math.floor(magnitude))))
    signed = param.is_coordinate and low < 0
    name = f"{'coordinate' if signed else 'number'}-{digits}"
    if name not in rules:
        integer = '("0" | [1-9]' + (f" [0-9]{{0,{digits - 1}}}" if digits > 1 else "") + ")"
        fraction = f'("." [0-9]{{1,{MAX_FRACTION_DIGITS}}})?'
        rules[name] = ('"-"? ' if signed else "") + f"{integer} {fraction}"
    return name


def _object_rule(objects: Sequence[str] | None) -> str:
    if objects is None:
        return "[a-zA-Z_] [a-zA-Z0-9_]{0,31}"
    return " | ".join(f'"{name}"' for name in sorted(set(objects)))
