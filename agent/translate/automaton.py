"""The canonical RSL language as a character automaton, built from the profile.

It accepts exactly what `rsl.grammar.to_gbnf` accepts (one `kw a, b;` per
line, closed by a blank line), optionally narrowed to some skills, objects
and number spellings. The token masks for grammar-limited sampling are
computed by walking the model's vocabulary through it, which is far cheaper
than llama.cpp's GBNF sampler on a 262k-token vocabulary.
"""

from __future__ import annotations

import math
import string
from collections.abc import Collection, Mapping, Sequence
from typing import Any

from rsl.grammar import MAX_FRACTION_DIGITS
from rsl.profile import IDENTIFIER, Param, Profile, Skill
from rsl.syntax import NO_PROGRAM

State = tuple[Any, ...]

START: State = ("S", False)
END: State = ("END",)
MAX_IDENTIFIER = 32
_IDENT_FIRST = frozenset(string.ascii_letters + "_")
_IDENT_REST = frozenset(string.ascii_letters + string.digits + "_")
ALPHABET = frozenset(string.ascii_letters + string.digits + "_.,;- \n" + NO_PROGRAM)


class RslAutomaton:
    """`step(state, char)` walks one character; `None` means the text left the language."""

    def __init__(self, profile: Profile, *, keywords: Collection[str] | None = None,
                 objects: Sequence[str] | None = None, numbers: Mapping[str, Collection[str]] | None = None,
                 max_statements: int | None = None, refusal: bool = False) -> None:
        if objects is not None:
            bad = [o for o in objects if not IDENTIFIER.match(o)]
            if bad:
                raise ValueError(f"object names must be C identifiers: {', '.join(map(repr, bad))}")
        self.objects = None if objects is None else tuple(sorted(set(objects)))
        # Number spellings allowed per unit ("m", "rad"); a unit with none left is free.
        self.numbers = None if numbers is None else {u: frozenset(v) for u, v in numbers.items() if v}
        allowed = set(profile.keywords if keywords is None else keywords)
        self.skills: dict[str, Skill] = {
            s.keyword: s for s in profile.skills
            if s.keyword in allowed and (self.objects or self.objects is None
                                         or all(p.kind != "object" for p in s.params))
        }
        if not self.skills:
            raise ValueError("the narrowed grammar allows no statement at all")
        # The decoder ends the program at this many statements, so a run-on
        # model repeating its last line stops; the compiler's cap stays the law.
        self.max_statements = max_statements or profile.max_statements
        # With `refusal`, the program may instead be the single line NO_PROGRAM.
        self.refusal = refusal
        self.key = (tuple(sorted(self.skills)), self.objects,
                    None if self.numbers is None else tuple(sorted((u, tuple(sorted(v)))
                                                                   for u, v in self.numbers.items())),
                    self.max_statements, refusal)
        self._number_shape = {(s.keyword, i): _number_shape(p) for s in self.skills.values()
                              for i, p in enumerate(s.params) if p.kind == "number"}
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
        return self.walk(START, text) == END

    def _step(self, state: State, char: str) -> State | None:
        kind = state[0]
        if kind == "S":
            if char == "\n" and state[1]:
                return END
            if self.refusal and not state[1] and char == NO_PROGRAM[0]:
                return ("R", 1)
            return self._keyword(char)
        if kind == "R":
            return self._in_refusal(state[1], char)
        if kind == "K":
            return self._in_keyword(state[1], char)
        if kind == "C":
            return self._param_start(state[1], state[2]) if char == " " else None
        if kind == "P":
            return self._in_param(state, char)
        if kind == "NL":
            return ("S", True) if char == "\n" else None
        return None

    def _in_refusal(self, matched: int, char: str) -> State | None:
        """The refusal line, then its newline, then the blank line that ends every program."""
        line = NO_PROGRAM + "\n"
        if matched < len(line):
            return ("R", matched + 1) if char == line[matched] else None
        return END if char == "\n" else None

    def _keyword(self, prefix_char: str) -> State | None:
        return ("K", prefix_char) if any(k.startswith(prefix_char) for k in self.skills) else None

    def _in_keyword(self, prefix: str, char: str) -> State | None:
        skill = self.skills.get(prefix)
        if skill is not None:
            if char == ";" and not skill.params:
                return ("NL",)
            if char == " " and skill.params:
                return self._param_start(prefix, 0)
        longer = prefix + char
        return ("K", longer) if any(k.startswith(longer) for k in self.skills) else None

    def _param_start(self, keyword: str, index: int) -> State:
        param = self.skills[keyword].params[index]
        if param.kind == "object":
            return ("P", keyword, index, "o", "")
        if self._literals(keyword, index):
            return ("P", keyword, index, "l", "")
        return ("P", keyword, index, "n", "start")

    def _literals(self, keyword: str, index: int) -> frozenset[str]:
        if self.numbers is None:
            return frozenset()
        signed = self._number_shape[(keyword, index)][1]
        unit = self.skills[keyword].params[index].unit
        # "keyword#index" pins one argument (the x of `goto`), "keyword:unit"
        # narrows one skill ("0.2618 rad when turning"); the unit is the fallback.
        allowed = (self.numbers.get(f"{keyword}#{index}") or self.numbers.get(f"{keyword}:{unit}")
                   or self.numbers.get(unit, frozenset()))
        return frozenset(n for n in allowed if signed or (not n.startswith("-") and float(n) > 0))

    def _param_done(self, keyword: str, index: int, char: str) -> State | None:
        count = len(self.skills[keyword].params)
        if char == "," and index + 1 < count:
            return ("C", keyword, index + 1)
        if char == ";" and index + 1 == count:
            return ("NL",)
        return None

    def _in_param(self, state: State, char: str) -> State | None:
        _, keyword, index, sub, value = state
        if char in ",;":
            return self._param_done(keyword, index, char) if self._complete(keyword, index, sub, value) else None
        if sub == "o":
            return self._in_object(keyword, index, value, char)
        if sub == "l":
            longer = value + char
            ok = any(n.startswith(longer) for n in self._literals(keyword, index))
            return ("P", keyword, index, "l", longer) if ok else None
        phase = _number_phase(value, char, *self._number_shape[(keyword, index)])
        return None if phase is None else ("P", keyword, index, "n", phase)

    def _in_object(self, keyword: str, index: int, value: Any, char: str) -> State | None:
        if self.objects is not None:
            longer = value + char
            ok = any(o.startswith(longer) for o in self.objects)
            return ("P", keyword, index, "o", longer) if ok else None
        # A free identifier is tracked by its length only, which keeps the
        # number of states (and token masks) small.
        length = len(value) if isinstance(value, str) else value
        allowed = _IDENT_FIRST if length == 0 else _IDENT_REST
        if char not in allowed or length + 1 > MAX_IDENTIFIER:
            return None
        return ("P", keyword, index, "o", length + 1)

    def _complete(self, keyword: str, index: int, sub: str, value: Any) -> bool:
        if sub == "o":
            return value in self.objects if self.objects is not None else bool(value)
        if sub == "l":
            return value in self._literals(keyword, index)
        return value == "zero" or (isinstance(value, tuple) and value[1] >= 1)

    def to_gbnf(self) -> str:
        """The same narrowed language as a llama.cpp GBNF grammar (for HTTP backends)."""
        rules: dict[str, str] = {}
        alternatives = []
        for skill in self.skills.values():
            parts = [self._gbnf_param(skill.keyword, i, p, rules) for i, p in enumerate(skill.params)]
            body = f'"{skill.keyword} " ' + ' ", " '.join(parts) + ' ";"' if parts else f'"{skill.keyword};"'
            alternatives.append(body)
        root = 'root ::= statement+ "\\n"' + (f' | "{NO_PROGRAM}\\n\\n"' if self.refusal else "")
        lines = [root, f'statement ::= ({" | ".join(alternatives)}) "\\n"']
        lines.extend(f"{name} ::= {body}" for name, body in rules.items())
        return "\n".join(lines) + "\n"

    def _gbnf_param(self, keyword: str, index: int, param: Param, rules: dict[str, str]) -> str:
        if param.kind == "object":
            if self.objects is None:
                rules["object"] = f"[a-zA-Z_] [a-zA-Z0-9_]{{0,{MAX_IDENTIFIER - 1}}}"
            else:
                rules["object"] = " | ".join(f'"{o}"' for o in self.objects)
            return "object"
        digits, signed = self._number_shape[(keyword, index)]
        literals = self._literals(keyword, index)
        if literals:
            name = f"{'coordinate' if signed else 'number'}-{param.unit or 'plain'}-literal"
            rules[name] = " | ".join(f'"{n}"' for n in sorted(literals))
            return name
        name = f"{'coordinate' if signed else 'number'}-{digits}"
        integer = '("0" | [1-9]' + (f" [0-9]{{0,{digits - 1}}}" if digits > 1 else "") + ")"
        rules[name] = ('"-"? ' if signed else "") + f'{integer} ("." [0-9]{{1,{MAX_FRACTION_DIGITS}}})?'
        return name


def _number_shape(param: Param) -> tuple[int, bool]:
    """(integer digits, may be negative), the same as `rsl.grammar` derives them."""
    high = param.max if param.max is not None else 99.0
    low = param.min if param.min is not None else 0.0
    digits = max(1, len(str(math.floor(max(abs(high), abs(low))))))
    return digits, bool(param.is_coordinate and low < 0)


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
    if not char.isdigit():
        return None
    if isinstance(phase, tuple) and phase[0] == "int" and phase[1] < digits:
        return ("int", phase[1] + 1)
    if phase == "dot":
        return ("frac", 1)
    if isinstance(phase, tuple) and phase[0] == "frac" and phase[1] < MAX_FRACTION_DIGITS:
        return ("frac", phase[1] + 1)
    return None
