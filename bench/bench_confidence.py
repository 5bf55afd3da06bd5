"""Knowing when not to act: how often a wrong program would run without a question, and what asking costs.

Translates every task of a suite with the shipped adapter and, for each,
records whether the plan is right (the suite's `accepts`), its confidence and
whether the default policy (`translator.confirm = "unsure"`) would ask.
Writes aggregates only:

- wrong_runs_unasked: share of all items that end as a wrong program the robot would run without asking;
- right_questioned: share of the right programs the policy would question;
- refusal: share of non-tasks with no program, and of tasks refused as non-tasks;
- auroc: how well the confidence ranks right plans above wrong ones (verified plans only);
- coverage_curve: accuracy of the plans kept when only those at or above a confidence are run;
- questioned_by: for right and wrong plans the policy questions, how many each meaning check doubted;
- checks_ms p50/p95: the added time of the meaning checks, explanation and confidence per translation;
- guessing_curve: what the first-token check (E201) would give at other thresholds than GUESSING_BELOW. Exact,
  not a model: that check reads only the first pass's first token, before anything else can differ;
- doubted_guessing_curve: the same, refusing only plans a meaning check doubts.

    python bench/bench_confidence.py [--suite FILE] [--out FILE] [--every K]

The frozen development set (bench/fresh/dev.toml) is measured, never tuned on: per-task results are
written only for the evaluation suite, which the thresholds were chosen on.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from agent.evalsuite import load_suite
from agent.evalsuite.runner import percentile
from agent.evalsuite.suite import accepts, suite_path
from agent.translate import Translator
from agent.translate.confidence import UNSURE_BELOW, assess, result_fields
from agent.translate.engine import Generation
from agent.translate.misheard import heard
from agent.translate.translator import GUESSING_BELOW, task_reading
from bench import SPLIT
from rsl.profile import load_profile


def auroc(positives: list[float], negatives: list[float]) -> float | None:
    """The chance a right plan scores above a wrong one (ties count half)."""
    if not positives or not negatives:
        return None
    wins = sum(1.0 if p > n else 0.5 if p == n else 0.0 for p in positives for n in negatives)
    return wins / (len(positives) * len(negatives))


def questioned_by(rows: list[dict[str, Any]]) -> dict[str, int]:
    """How many of the questioned plans in `rows` each meaning check doubted."""
    counted: Counter[str] = Counter()
    for row in rows:
        if row["confirm"]:
            counted.update(row["checks"] or ["model"])
    return dict(sorted(counted.items()))


def guessing_curve(rows: list[dict[str, Any]], *, doubted_only: bool = False) -> list[dict[str, Any]]:
    """For first-token thresholds from GUESSING_BELOW to 1, the outcomes if clauses the model started less
    surely than that had been refused as non-tasks too; with `doubted_only`, only those whose plan a meaning
    check doubts."""
    curve = []
    for step in range(round(GUESSING_BELOW * 20), 21):
        threshold = step / 20
        outcome = []
        for row in rows:
            reading = row["first_reading"]
            if reading is not None and reading < threshold and (row["checks"] or not doubted_only):
                row = {**row, "verified": False, "right": False, "confirm": False, "refused": True}
            outcome.append(row)
        tasks = [r for r in outcome if not r["refuse"]]
        right = [r for r in outcome if r["verified"] and r["right"]]
        curve.append({"threshold": threshold,
                      "non_tasks_without_program": sum(1 for r in outcome if r["refuse"] and not r["verified"]),
                      "tasks_refused": sum(1 for r in tasks if r["refused"]),
                      "right_programs": len(right), "right_questioned": sum(1 for r in right if r["confirm"]),
                      "wrong_runs_unasked": sum(1 for r in outcome
                                                if r["verified"] and not r["right"] and not r["confirm"])})
    return curve


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--suite", metavar="FILE", help="suite file (default: the evaluation suite)")
    parser.add_argument("--every", type=int, default=1, metavar="K", help="only every K-th task (default: all)")
    parser.add_argument("--out", default="bench/results/confidence_suite.json")
    parser.add_argument("--adapter", default="default", metavar="PATH",
                        help="adapter GGUF to measure (default: the shipped one)")
    parser.add_argument("--split", choices=tuple(SPLIT), default="default",
                        help="clause splitting (default: the translator's default for the adapter)")
    parser.add_argument("--per-task", action="store_true",
                        help="also write each task's outcome (only for sets that may be looked at)")
    args = parser.parse_args()

    profile = load_profile()
    tasks = load_suite(args.suite, profile)[:: max(1, args.every)]
    translator = Translator.load(profile, adapter=args.adapter,
                                 split_clauses=SPLIT[args.split])
    # The first pass's first generation of each translation: the one the first-token check reads.
    firsts: list[Generation] = []
    generate = translator.engine.generate

    def recording(*args: Any, **kwargs: Any) -> Generation:
        generation = generate(*args, **kwargs)
        firsts.append(generation)
        return generation

    translator.engine.generate = recording  # type: ignore[method-assign]
    rows: list[dict[str, Any]] = []
    checks_ms: list[float] = []
    started = time.monotonic()
    for index, task in enumerate(tasks, 1):
        firsts.clear()
        result = translator.translate(task.task, known_objects=task.objects)
        checks: list[str] = []
        if result.plan is not None:
            # The checks, explanation and confidence again, timed alone and side by side with the translation.
            begin = time.perf_counter()
            assessment = assess(heard(task.task, profile), result.plan, profile, known_objects=task.objects)
            result_fields(result.plan, profile, assessment)
            checks_ms.append((time.perf_counter() - begin) * 1000)
            # The translator's own: a plan read again a clause at a time carries a doubt no check of it has.
            checks = sorted(set(result.doubted_by))
        rows.append({"task": task.task, "group": task.group, "refuse": task.refuse, "program": result.program,
                     "verified": result.verified, "right": accepts(task, result.plan, profile),
                     "confidence": result.confidence, "confirm": result.confirm, "refused": result.refused,
                     "doubts": list(result.doubts), "checks": checks,
                     "first_reading": (task_reading(firsts[0], profile)
                                       if firsts and translator.options.refuse_unclear else None),
                     "total_ms": result.timings_ms.get("total", 0.0)})
        print(f"\r{index}/{len(tasks)} {time.monotonic() - started:.0f} s", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    translator.close()

    items = len(rows)
    real = [r for r in rows if not r["refuse"]]
    chat = [r for r in rows if r["refuse"]]
    ran = [r for r in rows if r["verified"]]
    right = [r for r in ran if r["right"]]
    wrong = [r for r in ran if not r["right"]]
    curve = []
    for threshold in (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 1.0):
        kept = [r for r in ran if (r["confidence"] or 0.0) >= threshold]
        curve.append({"threshold": threshold, "coverage": len(kept) / len(ran) if ran else 0.0,
                      "accuracy": sum(r["right"] for r in kept) / len(kept) if kept else None})
    summary: dict[str, Any] = {
        "suite": str(args.suite or suite_path()),
        "adapter": args.adapter, "split": args.split,
        "accuracy": sum(r["right"] for r in rows) / items if items else None,
        "items": items, "tasks": len(real), "non_tasks": len(chat),
        "unsure_below": UNSURE_BELOW,
        "wrong_runs_unasked": sum(1 for r in wrong if not r["confirm"]) / items,
        "wrong_runs_if_never_asked": len(wrong) / items,
        "wrong_runs_questioned": sum(1 for r in wrong if r["confirm"]) / len(wrong) if wrong else None,
        "right_questioned": sum(1 for r in right if r["confirm"]) / len(right) if right else None,
        "right_programs": len(right), "wrong_programs": len(wrong),
        # Which check put each questioned plan in doubt ("model": none did, the model's own signal was low).
        "questioned_by": {"right": questioned_by(right), "wrong": questioned_by(wrong)},
        "non_tasks_refused": sum(1 for r in chat if not r["verified"]) / len(chat) if chat else None,
        "non_tasks_refused_e201": sum(1 for r in chat if r["refused"]) / len(chat) if chat else None,
        "non_tasks_asked_or_refused": (sum(1 for r in chat if not r["verified"] or r["confirm"]) / len(chat)
                                       if chat else None),
        "tasks_refused_e201": sum(1 for r in real if r["refused"]) / len(real) if real else None,
        "tasks_right": sum(1 for r in real if r["right"]) / len(real) if real else None,
        "right_by_group": {group: sum(r["right"] for r in rows if r["group"] == group)
                           / sum(1 for r in rows if r["group"] == group)
                           for group in dict.fromkeys(r["group"] for r in rows)},
        "auroc": auroc([r["confidence"] for r in right], [r["confidence"] for r in wrong]),
        "coverage_curve": curve,
        "guessing_below": GUESSING_BELOW, "guessing_curve": guessing_curve(rows),
        "doubted_guessing_curve": guessing_curve(rows, doubted_only=True),
        "checks_ms_p50": percentile(checks_ms, 0.5), "checks_ms_p95": percentile(checks_ms, 0.95),
        "translate_ms_p50": percentile([r["total_ms"] for r in rows], 0.5),
        "machine": {"cpus": os.cpu_count(), "load_avg": os.getloadavg(), "python": platform.python_version(),
                    "note": "2 shared cores, other helpers running at the same time"},
        "wall_s": round(time.monotonic() - started, 1),
    }
    if args.per_task:
        summary["per_task"] = rows
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    curves = ("per_task", "coverage_curve", "guessing_curve", "doubted_guessing_curve")
    print(json.dumps({k: v for k, v in summary.items() if k not in curves}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
