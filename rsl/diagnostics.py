"""Compiler diagnostics: stable codes, positions, and messages people and LLMs can act on."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Any


class Code(Enum):
    """Every error the compiler reports. Codes are stable: tools match on them."""

    KEYWORD_CASE = ("E001", "keyword case")
    ILLEGAL_IDENTIFIER = ("E002", "illegal identifier")
    ILLEGAL_NUMBER = ("E003", "illegal number")
    ILLEGAL_CHARACTER = ("E004", "illegal character")
    BAD_COMMENT = ("E005", "bad comment")
    UNKNOWN_COMMAND = ("E006", "unknown command")
    PARAMETER_TYPE = ("E007", "wrong parameter type")
    PARAMETER_COUNT = ("E008", "wrong parameter count")
    MISSING_SEMICOLON = ("E009", "missing semicolon")
    MISSING_COMMA = ("E010", "missing comma")
    OUT_OF_RANGE = ("E101", "value out of range")
    NOT_POSITIVE = ("E102", "value not positive")
    OUTSIDE_WORKSPACE = ("E103", "target outside workspace")
    UNKNOWN_OBJECT = ("E104", "unknown object")
    TOO_LONG = ("E105", "program too long")
    # Reported by the translator, not the compiler: the words are not a task for this robot.
    NOT_A_TASK = ("E201", "not a robot task")

    def __init__(self, code: str, title: str) -> None:
        self.code = code
        self.title = title

    @property
    def is_semantic(self) -> bool:
        return self.code.startswith("E1")


@dataclass(frozen=True)
class Diagnostic:
    code: Code
    line: int
    column: int
    token: str
    message: str
    source_line: str

    def render(self) -> str:
        """Rust-style: header, location, the source line and a caret underline."""
        gutter = " " * len(str(self.line))
        width = max(1, len(self.token.splitlines()[0]) if self.token else 1)
        caret = " " * (self.column - 1) + "^" * width
        return (
            f"error[{self.code.code}]: {self.code.title}\n"
            f"{gutter}--> line {self.line}, column {self.column}\n"
            f"{gutter} |\n"
            f"{self.line} | {self.source_line}\n"
            f"{gutter} | {caret} {self.message}\n"
        )

    def brief(self) -> str:
        """One line for the LLM repair prompt and for logs."""
        return f"line {self.line}, column {self.column}: {self.message}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "code": self.code.code,
            "kind": self.code.title,
            "line": self.line,
            "column": self.column,
            "token": self.token,
            "message": self.message,
            "source_line": self.source_line,
        }
