"""RSL lexical grammar, in pyparsing.

The lexer never fails: text that is not a valid token becomes a token of a
"bad" kind, so the parser can report it with its exact position and keep
going. All alternatives live in one pyparsing `Regex` with named groups;
a `MatchFirst` of separate elements would raise and catch an exception per
failed alternative and was several times slower on long programs.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass
from enum import Enum

import pyparsing as pp

from rsl.syntax import COMMENT, DECIMAL, IDENTIFIER, SEPARATOR, TERMINATOR


class Kind(Enum):
    NUMBER = "number"
    IDENT = "identifier"
    SEMI = ";"
    COMMA = ","
    COMMENT = "comment"
    # Malformed input, kept as tokens so every error gets reported in one pass.
    BAD_NUMBER = "bad number"
    BAD_IDENT = "bad identifier"
    BAD_COMMENT = "bad comment"
    ILLEGAL = "illegal character"


# Order matters: earlier alternatives win at the same position.
_PATTERNS: tuple[tuple[Kind, str], ...] = (
    (Kind.COMMENT, COMMENT),
    # An unterminated block comment runs to the end; a lone `/` swallows its
    # line, since the writer almost certainly meant a `//` comment there.
    (Kind.BAD_COMMENT, r"/\*[\s\S]*|/[^\n]*"),
    # C's other integer spellings, hexadecimal `0x10`, binary `0b1` and octal
    # `010`, are not RSL numbers; a C reader would take `010` for 8.
    (Kind.BAD_NUMBER, r"[-+]?0[xXbBoO][\w.]*|[-+]?0[0-9]+(?![\w.])"),
    # A C decimal: digits with an optional fraction and exponent. The sign is
    # lexed with the number so `-1` can be reported as "not positive".
    (Kind.NUMBER, rf"[-+]?{DECIMAL}(?![\w.])"),
    # Starts with a digit but runs on with letters and no dot: `3apple`.
    (Kind.BAD_IDENT, r"[0-9]+[A-Za-z_]\w*(?![\w.])"),
    (Kind.BAD_NUMBER, r"[-+]?(?:\d|\.\d)[\w.]*"),
    (Kind.IDENT, rf"{IDENTIFIER}(?!\w)"),
    # A word with a non-ASCII letter or digit (`café`, `x²`): one bad name, not a name and junk.
    (Kind.BAD_IDENT, r"\w+"),
    (Kind.SEMI, re.escape(TERMINATOR)),
    (Kind.COMMA, re.escape(SEPARATOR)),
    # Anything else that is not C whitespace, including Unicode spaces and
    # control characters, which would otherwise vanish without a word.
    (Kind.ILLEGAL, r"[^ \t\r\n\f\v]"),
)

_GROUP = {f"k{i}": kind for i, (kind, _) in enumerate(_PATTERNS)}
_TOKEN_RE = pp.Regex("|".join(f"(?P<k{i}>{pattern})" for i, (_, pattern) in enumerate(_PATTERNS))).re

# The shape of an ordinary statement, matched as one lexeme: scanning once
# per statement instead of once per token is what keeps a 10,000-statement
# program well under the 0.5 s budget. Its inside is then split with the
# token patterns above, so both paths yield the same tokens.
_ARG = r"[-+]?[\w.]+"
_STATEMENT_RUN = rf"{IDENTIFIER}(?:[ \t]+{_ARG}(?:[ \t]*,[ \t]*{_ARG})*)?[ \t]*;"
# No named groups here: pyparsing copies every group into its results, and
# that bookkeeping cost more than the scan itself.
_LEXEME = pp.Regex("|".join([_STATEMENT_RUN, *(f"(?:{pattern})" for _, pattern in _PATTERNS)]))
_LEXEME.leave_whitespace()
# Offsets must index the original text; pyparsing expands tabs unless told not to.
_LEXEME.parse_with_tabs()


@dataclass(frozen=True, slots=True)
class Token:
    kind: Kind
    text: str
    offset: int
    line: int
    column: int


class SourceMap:
    """Offsets to 1-based line and column, and the text of a line."""

    def __init__(self, source: str) -> None:
        self.source = source
        self._starts = [0]
        self._starts.extend(i + 1 for i, ch in enumerate(source) if ch == "\n")

    def position(self, offset: int) -> tuple[int, int]:
        index = bisect.bisect_right(self._starts, offset) - 1
        return index + 1, offset - self._starts[index] + 1

    def line_text(self, line: int) -> str:
        start = self._starts[line - 1]
        end = self.source.find("\n", start)
        return self.source[start:] if end < 0 else self.source[start:end]


def tokenize(source: str, source_map: SourceMap | None = None) -> list[Token]:
    """Every token of `source`, comments included, in order."""
    positions = source_map or SourceMap(source)
    tokens: list[Token] = []
    for _match, start, end in _LEXEME.scan_string(source):
        line, column = positions.position(start)
        found = _TOKEN_RE.match(source, start, end)
        if found is not None and found.end() == end:
            tokens.append(Token(_GROUP[str(found.lastgroup)], found.group(), start, line, column))
            continue
        for piece in _TOKEN_RE.finditer(source, start, end):
            # A statement run never spans a newline, so only the column moves.
            tokens.append(Token(_GROUP[str(piece.lastgroup)], piece.group(), piece.start(), line,
                                column + piece.start() - start))
    return tokens
