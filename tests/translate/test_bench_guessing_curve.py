"""bench_confidence's what-if curves for the first-token check: what refusing below a threshold would do."""

from __future__ import annotations

from typing import Any

from bench.bench_confidence import guessing_curve


def row(reading: float | None, *, refuse: bool = False, right: bool = True, checks: tuple[str, ...] = (),
        confirm: bool = False) -> dict[str, Any]:
    return {"first_reading": reading, "refuse": refuse, "verified": True, "right": right, "checks": list(checks),
            "confirm": confirm, "refused": False}


ROWS = [
    row(0.99),                                                       # a sure task, right
    row(0.6),                                                        # a right task started less surely
    row(0.6, refuse=True, right=False, checks=("motion",), confirm=True),  # a non-task the checks doubt
    row(0.8, right=False),                                           # a wrong program run unasked
    row(None),                                                       # no first-token reading: never refused
]


def at(curve: list[dict[str, Any]], threshold: float) -> dict[str, Any]:
    return next(point for point in curve if point["threshold"] == threshold)


def test_refusing_below_a_threshold_counts_what_it_costs_and_gains() -> None:
    curve = guessing_curve(ROWS)
    assert at(curve, 0.5) == {"threshold": 0.5, "non_tasks_without_program": 0, "tasks_refused": 0,
                              "right_programs": 3, "right_questioned": 0, "wrong_runs_unasked": 1}
    assert at(curve, 0.65)["non_tasks_without_program"] == 1 and at(curve, 0.65)["tasks_refused"] == 1
    assert at(curve, 0.65)["right_programs"] == 2
    assert at(curve, 0.85)["wrong_runs_unasked"] == 0 and at(curve, 0.85)["tasks_refused"] == 2
    assert at(curve, 1.0)["right_programs"] == 1


def test_the_doubted_curve_refuses_only_plans_a_check_doubts() -> None:
    curve = guessing_curve(ROWS, doubted_only=True)
    assert at(curve, 1.0) == {"threshold": 1.0, "non_tasks_without_program": 1, "tasks_refused": 0,
                              "right_programs": 3, "right_questioned": 0, "wrong_runs_unasked": 1}
