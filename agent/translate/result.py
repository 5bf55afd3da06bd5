"""The records a translation produces: every attempt, and the final verdict."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from rsl.diagnostics import Code, Diagnostic
from rsl.plan import Plan


@dataclass(frozen=True)
class Attempt:
    """One generated candidate and what the compiler said about it."""

    program: str
    diagnostics: tuple[Diagnostic, ...]

    @property
    def ok(self) -> bool:
        return not self.diagnostics

    def to_json_dict(self) -> dict[str, Any]:
        return {"program": self.program, "diagnostics": [d.to_dict() for d in self.diagnostics]}


@dataclass(frozen=True)
class TranslationResult:
    """The outcome of `Translator.translate`; `plan` is set only when verified."""

    task: str
    program: str
    verified: bool
    passes: int
    attempts: tuple[Attempt, ...]
    plan: Plan | None
    model: str
    timings_ms: dict[str, float] = field(default_factory=dict)
    # The plan in plain words ("drive forward 3 m, then turn right 90°"); empty without a plan.
    explanation: str = ""
    # How sure the translation is that the plan is what was meant; None without a plan.
    confidence: float | None = None
    # Why it is unsure, one reason a person can read per entry.
    doubts: tuple[str, ...] = ()
    # The meaning checks behind `doubts`, one name each ("part", "whole"), for measuring them.
    doubted_by: tuple[str, ...] = ()
    # Whether the default policy (`confirm = "unsure"`) asks before the plan runs.
    confirm: bool = False

    @property
    def refused(self) -> bool:
        """Whether the task was not read as a task for the robot, rather than written wrongly."""
        return bool(self.attempts) and any(d.code is Code.NOT_A_TASK for d in self.attempts[-1].diagnostics)

    def to_json_dict(self) -> dict[str, Any]:
        """The `nrtrans translate --json` contract; keep the keys stable."""
        return {
            "task": self.task,
            "program": self.program,
            "verified": self.verified,
            "passes": self.passes,
            "attempts": [a.to_json_dict() for a in self.attempts],
            "plan": self.plan.to_list() if self.plan is not None else [],
            "model": self.model,
            "timings_ms": {k: round(v, 3) for k, v in self.timings_ms.items()},
            "explanation": self.explanation,
            "confidence": self.confidence,
            "doubts": list(self.doubts),
            "confirm": self.confirm,
            "refused": self.refused,
        }
