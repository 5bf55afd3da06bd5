"""The one description of RSL's surface syntax that every reader and writer of programs shares.

It describes two languages from the same parts. The compiler reads the
*written* language: tokens as below, free spacing and line breaks, comments.
The translator's decoding automaton and its GBNF grammars produce the
*canonical* language, a subset: one `keyword arg, arg;` per line, numbers as
plain decimals of bounded length, at most `max_statements` lines, closed by a
blank line, or instead the single line `NO_PROGRAM`. `syntax_of` derives the
canonical statements from the profile, optionally narrowed.
"""

from __future__ import annotations

import math
import re
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

from rsl.profile import Param, Profile

# Tokens of the written language, as regular expressions. Names and numbers are
# ASCII only: they end up in generated code, logs and ROS messages.
IDENTIFIER = r"[A-Za-z_][A-Za-z0-9_]*"
DECIMAL = r"(?:[0-9]+\.[0-9]*|\.[0-9]+|[0-9]+)(?:[eE][-+]?[0-9]+)?"
COMMENT = r"//[^\n]*|/\*[\s\S]*?\*/"
TERMINATOR = ";"
SEPARATOR = ","

# The canonical spelling (what `Plan.to_rsl` prints and the decoder may write).
KEYWORD_GAP = " "
ARGUMENT_SEPARATOR = SEPARATOR + " "
LINE_END = "\n"
# A program ends on a blank line: "\n\n" is one token in most vocabularies, so
# the model has a natural way to stop, and the grammar must be able to accept it.
PROGRAM_END = "\n"
MAX_IDENTIFIER = 32
MAX_FRACTION_DIGITS = 4
# What a model writes, in place of a program, for words that are not a task for
# this robot. It is a comment, so it also compiles, to an empty plan.
NO_PROGRAM = "// no program"

_IDENTIFIER_RE = re.compile(IDENTIFIER + r"\Z")


def is_identifier(name: str) -> bool:
    return bool(_IDENTIFIER_RE.match(name))


@dataclass(frozen=True)
class NumberShape:
    """A canonical number: `digits` integer digits at most, a `-` when `signed`, or one of `literals`."""

    digits: int
    signed: bool
    literals: frozenset[str] | None = None

    def regex(self) -> str:
        if self.literals:
            return "(?:" + "|".join(re.escape(n) for n in sorted(self.literals)) + ")"
        sign = "-?" if self.signed else ""
        return rf"{sign}(?:0|[1-9][0-9]{{0,{self.digits - 1}}})(?:\.[0-9]{{1,{MAX_FRACTION_DIGITS}}})?"


@dataclass(frozen=True)
class ObjectShape:
    """An object name: one of `names`, or any identifier of at most MAX_IDENTIFIER characters."""

    names: tuple[str, ...] | None = None

    def regex(self) -> str:
        if self.names is not None:
            return "(?:" + "|".join(re.escape(n) for n in self.names) + ")"
        return rf"[A-Za-z_][A-Za-z0-9_]{{0,{MAX_IDENTIFIER - 1}}}"


Argument = NumberShape | ObjectShape


@dataclass(frozen=True)
class StatementShape:
    keyword: str
    args: tuple[Argument, ...]

    def regex(self) -> str:
        if not self.args:
            return re.escape(self.keyword + TERMINATOR)
        return (re.escape(self.keyword + KEYWORD_GAP) + re.escape(ARGUMENT_SEPARATOR).join(a.regex() for a in self.args)
                + re.escape(TERMINATOR))


@dataclass(frozen=True)
class Syntax:
    """The canonical language for one profile and narrowing."""

    statements: tuple[StatementShape, ...]
    max_statements: int
    refusal: bool = False

    def statement(self, keyword: str) -> StatementShape | None:
        return next((s for s in self.statements if s.keyword == keyword), None)

    def regex(self) -> re.Pattern[str]:
        """The whole canonical language as one regular expression (for checks and tests)."""
        line = "(?:" + "|".join(s.regex() for s in self.statements) + ")" + re.escape(LINE_END)
        program = f"(?:{line}){{1,{self.max_statements}}}" + re.escape(PROGRAM_END)
        if self.refusal:
            program = f"(?:{program}|{re.escape(NO_PROGRAM + LINE_END + PROGRAM_END)})"
        return re.compile(program)


def number_shape(param: Param) -> NumberShape:
    """The integer digits the parameter's range needs, and whether it may be negative.

    Only coordinates may be negative: a negative distance is written with the
    opposite skill, and the compiler says so.
    """
    high = param.max if param.max is not None else 99.0
    low = param.min if param.min is not None else 0.0
    digits = max(1, len(str(math.floor(max(abs(high), abs(low))))))
    return NumberShape(digits, bool(param.is_coordinate and low < 0))


def syntax_of(profile: Profile, *, keywords: Collection[str] | None = None, objects: Sequence[str] | None = None,
              numbers: Mapping[str, Collection[str]] | None = None, max_statements: int | None = None,
              refusal: bool = False) -> Syntax:
    """The canonical statements of `profile`, narrowed.

    `keywords` keeps only those skills; `objects` allows only those object
    names, and with an empty list leaves out the skills that need an object.
    `numbers` gives the spellings allowed per argument: the key
    "keyword#index" pins one argument (the x of `goto`), "keyword:unit" one
    skill's numbers of a unit ("0.2618 rad when turning"), and a plain unit is
    the fallback; an argument with no spelling left is free.
    """
    if objects is not None:
        bad = [o for o in objects if not is_identifier(o)]
        if bad:
            raise ValueError(f"object names must be ASCII C identifiers: {', '.join(map(repr, bad))}")
    names = None if objects is None else tuple(sorted(set(objects)))
    allowed = None if keywords is None else set(keywords)
    spellings = {k: frozenset(v) for k, v in (numbers or {}).items() if v}
    statements = []
    for skill in profile.skills:
        if allowed is not None and skill.keyword not in allowed:
            continue
        if names == () and any(p.kind == "object" for p in skill.params):
            continue
        args: list[Argument] = []
        for index, param in enumerate(skill.params):
            if param.kind == "object":
                args.append(ObjectShape(names))
                continue
            shape = number_shape(param)
            pinned = (spellings.get(f"{skill.keyword}#{index}") or spellings.get(f"{skill.keyword}:{param.unit}")
                      or spellings.get(param.unit, frozenset()))
            literals = frozenset(n for n in pinned if shape.signed or (not n.startswith("-") and float(n) > 0))
            args.append(NumberShape(shape.digits, shape.signed, literals or None))
        statements.append(StatementShape(skill.keyword, tuple(args)))
    if not statements:
        raise ValueError("the narrowed grammar allows no statement at all")
    return Syntax(tuple(statements), max_statements or profile.max_statements, refusal)
