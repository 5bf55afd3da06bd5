"""Running a translator over the suite and summarizing per group."""

from __future__ import annotations

import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from agent.evalsuite.suite import EvalTask, accepts
from rsl.profile import Profile


@dataclass(frozen=True)
class TaskOutcome:
    task: EvalTask
    program: str
    verified: bool
    accepted: bool
    passes: int
    latency_ms: float

    @property
    def wrong_runs(self) -> bool:
        """A verified program that is not what was asked: the robot would have moved wrongly."""
        return self.verified and not self.accepted

    def to_dict(self) -> dict[str, Any]:
        return {"group": self.task.group, "task": self.task.task, "program": self.program,
                "verified": self.verified, "accepted": self.accepted, "passes": self.passes,
                "latency_ms": round(self.latency_ms, 1), "holdout": self.task.holdout,
                "refuse": self.task.refuse}


def run_suite(translator: Any, tasks: Sequence[EvalTask], profile: Profile,
              progress: Callable[[int, int, TaskOutcome], None] | None = None) -> list[TaskOutcome]:
    outcomes = []
    for index, task in enumerate(tasks, start=1):
        try:
            result = translator.translate(task.task, known_objects=task.objects)
        except ValueError as exc:
            # A task the translator refuses (too long for the context) is a failed task, not a crashed run.
            outcome = TaskOutcome(task=task, program=f"<error: {exc}>", verified=False, accepted=False,
                                  passes=0, latency_ms=0.0)
        else:
            outcome = TaskOutcome(task=task, program=result.program, verified=result.verified,
                                  accepted=accepts(task, result.plan, profile), passes=result.passes,
                                  latency_ms=result.timings_ms.get("total", 0.0))
        outcomes.append(outcome)
        if progress is not None:
            progress(index, len(tasks), outcome)
    return outcomes


def percentile(values: Sequence[float], fraction: float) -> float:
    """Nearest-rank percentile; 0 for no values."""
    if not values:
        return 0.0
    ordered = sorted(values)
    rank = max(1, min(len(ordered), round(fraction * len(ordered) + 0.5)))
    return ordered[rank - 1]


def summarize(outcomes: Sequence[TaskOutcome]) -> dict[str, dict[str, float]]:
    """Per group (in the order they first appear) and `overall`.

    Each row: n, success (verified), accuracy, wrong_runs (verified but not
    what was asked), mean passes, latency p50/p95 (ms).
    """
    table: dict[str, dict[str, float]] = {}
    groups = dict.fromkeys(o.task.group for o in outcomes)
    buckets = [(g, [o for o in outcomes if o.task.group == g]) for g in groups]
    buckets.append(("overall", list(outcomes)))
    for name, group in buckets:
        if not group:
            continue
        latencies = [o.latency_ms for o in group]
        table[name] = {
            "n": len(group),
            "success": sum(o.verified for o in group) / len(group),
            "accuracy": sum(o.accepted for o in group) / len(group),
            "wrong_runs": sum(o.wrong_runs for o in group) / len(group),
            "mean_passes": statistics.fmean(o.passes for o in group),
            "latency_p50_ms": percentile(latencies, 0.5),
            "latency_p95_ms": percentile(latencies, 0.95),
        }
    return table


def render_table(table: dict[str, dict[str, float]]) -> str:
    header = (f"{'group':<14} {'n':>4} {'success':>8} {'accuracy':>9} {'wrong+ran':>10} {'passes':>7} "
              f"{'p50 ms':>8} {'p95 ms':>8}")
    lines = [header, "-" * len(header)]
    for name, row in table.items():
        lines.append(f"{name:<14} {int(row['n']):>4} {row['success']:>8.1%} {row['accuracy']:>9.1%} "
                     f"{row['wrong_runs']:>10.1%} {row['mean_passes']:>7.2f} {row['latency_p50_ms']:>8.0f} "
                     f"{row['latency_p95_ms']:>8.0f}")
    return "\n".join(lines)
