"""`nrtrans eval`: accuracy, success, passes and latency on the project's task suite."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

from agent.commands.translate import EXIT_USAGE, add_model_options, load_translator


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "eval", help="measure translation accuracy on the evaluation suite",
        description="Translate every task of the evaluation suite (agent/evalsuite/suite.toml) and check "
                    "each result against its accepted programs. Prints success (verified), accuracy "
                    "(accepted), mean passes and latency p50/p95 per group and overall.",
        epilog="Example: nrtrans eval --group units --out bench/results/eval.json")
    parser.add_argument("--group", action="append", metavar="NAME",
                        help="only this group (repeatable); the suite's groups are simple, ambiguous, "
                             "multi-step, complex, units and asr-noise, another --suite may name its own")
    parser.add_argument("--limit", type=int, metavar="N", help="only the first N tasks (after --group)")
    parser.add_argument("--every", type=int, default=1, metavar="K",
                        help="only every K-th task, a quick sample across all groups (default: 1, all)")
    parser.add_argument("--holdout", choices=["all", "only", "exclude"], default="all",
                        help="tasks kept out of development: all (default), only those, or none of them")
    parser.add_argument("--suite", metavar="FILE", help="another suite file in the same format")
    parser.add_argument("--out", metavar="FILE", help="write the table and every task's result as JSON here")
    parser.add_argument("-q", "--quiet", action="store_true", help="no per-task progress lines")
    add_model_options(parser)
    parser.set_defaults(func=_eval)


def _eval(args: argparse.Namespace) -> int:
    from agent.evalsuite.runner import render_table, run_suite, summarize
    from agent.evalsuite.suite import SuiteError, load_suite
    from agent.translate import ModelNotFoundError
    from agent.translate.http import EndpointError
    from rsl.profile import ProfileError, load_profile

    try:
        profile = load_profile(args.profile)
        tasks = list(load_suite(args.suite, profile))
    except (ProfileError, SuiteError) as exc:
        print(f"nrtrans eval: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    groups = list(dict.fromkeys(t.group for t in tasks))
    unknown = [g for g in args.group or [] if g not in groups]
    if unknown:
        print(f"nrtrans eval: error: unknown group {', '.join(unknown)}; use one of {', '.join(groups)}",
              file=sys.stderr)
        return EXIT_USAGE
    if args.group:
        tasks = [t for t in tasks if t.group in args.group]
    if args.holdout != "all":
        tasks = [t for t in tasks if t.holdout == (args.holdout == "only")]
    if args.every > 1:
        tasks = tasks[:: args.every]
    if args.limit is not None:
        tasks = tasks[: max(0, args.limit)]
    if not tasks:
        print("nrtrans eval: error: no task left after --group/--holdout/--limit", file=sys.stderr)
        return EXIT_USAGE
    print(f"loading the model ({len(tasks)} tasks to run) ...", file=sys.stderr)
    try:
        translator = load_translator(args)
    except (ModelNotFoundError, ProfileError, EndpointError, ValueError) as exc:
        print(f"nrtrans eval: error: {exc}", file=sys.stderr)
        return EXIT_USAGE

    def progress(index: int, total: int, outcome: Any) -> None:
        if args.quiet:
            return
        mark = "ok  " if outcome.accepted else ("VERI" if outcome.verified else "FAIL")
        program = " ".join(outcome.program.split())
        print(f"[{index:>3}/{total}] {mark} {outcome.latency_ms:6.0f} ms  {outcome.task.task!r} -> {program}",
              file=sys.stderr)

    started = time.perf_counter()
    try:
        outcomes = run_suite(translator, tasks, profile, progress)
    except EndpointError as exc:
        print(f"nrtrans eval: error: {exc}", file=sys.stderr)
        return 1
    finally:
        translator.close()
    table = summarize(outcomes)
    print(render_table(table))
    if args.out:
        report = {
            "model": translator.model_name,
            "options": vars(translator.options),
            "wall_s": round(time.perf_counter() - started, 1),
            "table": table,
            "tasks": [o.to_dict() for o in outcomes],
        }
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
        print(f"wrote {out}", file=sys.stderr)
    return 0
