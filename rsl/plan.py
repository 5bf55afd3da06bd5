"""The typed plan: what a verified RSL program compiles to, and what robots run."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Quantity:
    """A number with its unit as declared in the profile (`m`, `rad`)."""

    value: float
    unit: str

    def to_rsl(self) -> str:
        return format_number(self.value)


@dataclass(frozen=True)
class ObjectRef:
    """A named object; the name is a validated C identifier."""

    name: str

    def to_rsl(self) -> str:
        return self.name


Arg = Quantity | ObjectRef


@dataclass(frozen=True)
class Command:
    """One statement of a verified program, with where it came from."""

    skill: str
    args: tuple[Arg, ...]
    line: int
    column: int

    def number(self, index: int = 0) -> float:
        arg = self.args[index]
        if not isinstance(arg, Quantity):
            raise TypeError(f"argument {index} of `{self.skill}` is an object, not a number")
        return arg.value

    def object(self, index: int = 0) -> str:
        arg = self.args[index]
        if not isinstance(arg, ObjectRef):
            raise TypeError(f"argument {index} of `{self.skill}` is a number, not an object")
        return arg.name

    def reached_by(self, skill: str) -> Command:
        """The step of `skill` (this step's skill's `out_of_reach`) that brings the robot to this step's thing
        first: it takes the thing and stands where this step was written."""
        return Command(skill, self.args[:1], self.line, self.column)

    def to_rsl(self) -> str:
        """The one canonical spelling: `kw a, b;`."""
        if not self.args:
            return f"{self.skill};"
        return f"{self.skill} {', '.join(a.to_rsl() for a in self.args)};"

    def to_dict(self) -> dict[str, Any]:
        return {
            "skill": self.skill,
            "args": [
                {"value": a.value, "unit": a.unit} if isinstance(a, Quantity) else {"object": a.name}
                for a in self.args
            ],
            "line": self.line,
            "column": self.column,
            "rsl": self.to_rsl(),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Command:
        args: list[Arg] = [
            ObjectRef(str(a["object"])) if "object" in a else Quantity(float(a["value"]), str(a["unit"]))
            for a in data["args"]
        ]
        return cls(skill=str(data["skill"]), args=tuple(args),
                   line=int(data.get("line", 0)), column=int(data.get("column", 0)))


@dataclass(frozen=True)
class Plan:
    """An immutable, verified sequence of commands for one profile."""

    commands: tuple[Command, ...]
    profile: str

    def __len__(self) -> int:
        return len(self.commands)

    def __iter__(self) -> Iterator[Command]:
        return iter(self.commands)

    def to_rsl(self) -> str:
        return "".join(c.to_rsl() + "\n" for c in self.commands)

    def to_list(self) -> list[dict[str, Any]]:
        return [c.to_dict() for c in self.commands]


def format_number(value: float) -> str:
    """Canonical RSL spelling of a number: plain decimal, at most 4 decimals.

    Four decimals keep radians exact enough (0.1 mrad) and every printed
    number is accepted by the parser and the grammar alike.
    """
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text
