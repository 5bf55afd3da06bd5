"""The canonical RSL language as a character automaton, built from the profile.

It accepts the canonical language that `rsl.syntax` describes (one `kw a, b;`
per line, closed by a blank line), optionally narrowed to some skills, objects
and number spellings, exactly as the GBNF that `rsl.grammar` writes for it.
The token masks for grammar-limited sampling are computed by walking the
model's vocabulary through it, which is far cheaper than llama.cpp's GBNF
sampler on a 262k-token vocabulary.
"""

from __future__ import annotations

import string
from collections.abc import Collection, Mapping, Sequence
from typing import Any

from rsl.grammar import gbnf
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
    ObjectShape,
    StatementShape,
    syntax_of,
)

State = tuple[Any, ...]

START: State = ("S", False)
END: State = ("END",)
_IDENT_FIRST = frozenset(string.ascii_letters + "_")
_IDENT_REST = frozenset(string.ascii_letters + string.digits + "_")
_REFUSAL = NO_PROGRAM + LINE_END + PROGRAM_END
# Every character the canonical language can contain; the engine keeps only tokens spelled with these.
ALPHABET = frozenset(string.ascii_letters + string.digits + "_.-" + ARGUMENT_SEPARATOR + KEYWORD_GAP + TERMINATOR
                     + LINE_END + PROGRAM_END + NO_PROGRAM)


class RslAutomaton:
    """`step(state, char)` walks one character; `None` means the text left the language.

    The language is `rsl.syntax.syntax_of(profile, ...)` with the same
    narrowing arguments. The statement cap is not part of the state, so the
    token masks do not multiply by it: `accepts` counts statements, and the
    engine stops sampling new ones at `max_statements`.
    """

    def __init__(self, profile: Profile, *, keywords: Collection[str] | None = None,
                 objects: Sequence[str] | None = None, numbers: Mapping[str, Collection[str]] | None = None,
                 max_statements: int | None = None, refusal: bool = False) -> None:
        self.syntax = syntax_of(profile, keywords=keywords, objects=objects, numbers=numbers,
                                max_statements=max_statements, refusal=refusal)
        self.objects = None if objects is None else tuple(sorted(set(objects)))
        self.skills: dict[str, StatementShape] = {s.keyword: s for s in self.syntax.statements}
        # The decoder ends the program at this many statements, so a run-on
        # model repeating its last line stops; the compiler's cap stays the law.
        self.max_statements = self.syntax.max_statements
        self.refusal = refusal
        self.key = self.syntax
        self._memo: dict[tuple[State, str], State | None] = {}

    def step(self, state: State, char: str) -> State | None:
        key = (state, char)
        if key not in self._memo:
            self._memo[key] = self._step(state, char)
        return self._memo[key]

    def walk(self, state: State | None, text: str) -> State | None:
        for char in text:
            if state is None:
                return None
            state = self.step(state, char)
        return state

    def accepts(self, text: str) -> bool:
        """Whether `text` is a whole program of the language, within the statement cap."""
        statements = 0
        state: State | None = START
        for char in text:
            if state is None:
                return False
            state = self.step(state, char)
            statements += state == ("S", True)
        return state == END and statements <= self.max_statements

    def _step(self, state: State, char: str) -> State | None:
        kind = state[0]
        if kind == "S":
            if char == PROGRAM_END and state[1]:
                return END
            if self.refusal and not state[1] and char == _REFUSAL[0]:
                return ("R", 1)
            return self._keyword("", char)
        if kind == "R":
            if char != _REFUSAL[state[1]]:
                return None
            return END if state[1] + 1 == len(_REFUSAL) else ("R", state[1] + 1)
        if kind == "K":
            return self._in_keyword(state[1], char)
        if kind == "L":
            return self._in_literal(state, char)
        if kind == "P":
            return self._in_argument(state, char)
        return None

    def _keyword(self, prefix: str, char: str) -> State | None:
        longer = prefix + char
        return ("K", longer) if any(k.startswith(longer) for k in self.skills) else None

    def _in_keyword(self, prefix: str, char: str) -> State | None:
        statement = self.skills.get(prefix)
        if statement is not None:
            after = self._literal_start(prefix, 0, char)
            if after is not None:
                return after
        return self._keyword(prefix, char)

    def _follower(self, keyword: str, index: int) -> str:
        """The fixed text before argument `index`; after the last one, the statement's end."""
        args = self.skills[keyword].args
        if index == len(args):
            return TERMINATOR + LINE_END
        return KEYWORD_GAP if index == 0 else ARGUMENT_SEPARATOR

    def _literal_start(self, keyword: str, index: int, char: str) -> State | None:
        return self._in_literal(("L", keyword, index, 0), char)

    def _in_literal(self, state: State, char: str) -> State | None:
        _, keyword, index, matched = state
        text = self._follower(keyword, index)
        if char != text[matched]:
            return None
        if matched + 1 < len(text):
            return ("L", keyword, index, matched + 1)
        if index == len(self.skills[keyword].args):
            return ("S", True)
        return ("P", keyword, index, "")

    def _in_argument(self, state: State, char: str) -> State | None:
        _, keyword, index, value = state
        if self._complete(keyword, index, value):
            after = self._literal_start(keyword, index + 1, char)
            if after is not None:
                return after
        arg = self.skills[keyword].args[index]
        if isinstance(arg, ObjectShape):
            grown = _grow_object(arg, value, char)
        elif arg.literals:
            longer = value + char
            grown = longer if any(n.startswith(longer) for n in arg.literals) else None
        else:
            grown = _number_phase(value or "start", char, arg.digits, arg.signed)
        return None if grown is None else ("P", keyword, index, grown)

    def _complete(self, keyword: str, index: int, value: Any) -> bool:
        arg = self.skills[keyword].args[index]
        if isinstance(arg, ObjectShape):
            return value in arg.names if arg.names is not None else bool(value)
        if arg.literals:
            return value in arg.literals
        return value == "zero" or (isinstance(value, tuple) and value[1] >= 1)

    def to_gbnf(self) -> str:
        """The same narrowed language, statement cap included, as a llama.cpp GBNF grammar (for HTTP backends)."""
        return gbnf(self.syntax)


def _grow_object(arg: ObjectShape, value: Any, char: str) -> Any:
    if arg.names is not None:
        longer = value + char
        return longer if any(o.startswith(longer) for o in arg.names) else None
    # A free identifier is tracked by its length only, which keeps the
    # number of states (and token masks) small.
    length = value or 0
    allowed = _IDENT_FIRST if length == 0 else _IDENT_REST
    return length + 1 if char in allowed and length < MAX_IDENTIFIER else None


def _number_phase(phase: Any, char: str, digits: int, signed: bool) -> Any:
    """Number lexing: "start", "sign", "zero", ("int", n), "dot", ("frac", n)."""
    if phase in ("start", "sign"):
        if char == "-" and phase == "start" and signed:
            return "sign"
        if char == "0":
            return "zero"
        return ("int", 1) if char in "123456789" else None
    if char == ".":
        return "dot" if phase == "zero" or (isinstance(phase, tuple) and phase[0] == "int") else None
    if char not in string.digits:
        return None
    if isinstance(phase, tuple) and phase[0] == "int" and phase[1] < digits:
        return ("int", phase[1] + 1)
    if phase == "dot":
        return ("frac", 1)
    if isinstance(phase, tuple) and phase[0] == "frac" and phase[1] < MAX_FRACTION_DIGITS:
        return ("frac", phase[1] + 1)
    return None
