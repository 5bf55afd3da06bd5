"""`nrtrans eval` side by side: base model with shots vs the RSL adapter, each with and without the grammar.

Runs the whole evaluation suite four times in one process, one configuration
after another, on the same machine state, and writes per-group accuracy,
success (verified), mean passes and latency for each, plus the tasks each got
wrong. Writes bench/results/eval_side_by_side.json.

    python bench/bench_eval.py [--adapter PATH|default] [--suite FILE] [--every K] [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

from agent.evalsuite import load_suite
from agent.evalsuite.runner import render_table, run_suite, summarize
from agent.translate import Translator
from rsl.profile import load_profile

CONFIGURATIONS = (
    ("base, shots, no grammar", {"adapter": "none", "grammar": False}),
    ("base, shots, grammar", {"adapter": "none", "grammar": True}),
    ("adapter, no grammar", {"grammar": False}),
    ("adapter, grammar (default)", {"grammar": True}),
)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--adapter", default="default", help="adapter GGUF to measure (default: the shipped one)")
    parser.add_argument("--suite", metavar="FILE", help="another suite file (default: the evaluation suite)")
    parser.add_argument("--every", type=int, default=1, metavar="K", help="only every K-th task (default: all)")
    parser.add_argument("--out", default="bench/results/eval_side_by_side.json")
    args = parser.parse_args()

    profile = load_profile()
    tasks = list(load_suite(args.suite, profile=profile))[:: max(1, args.every)]
    runs: dict[str, dict[str, Any]] = {}
    for name, settings in CONFIGURATIONS:
        options = {"adapter": args.adapter, **settings}
        translator = Translator.load(profile, **options)
        started = time.perf_counter()
        outcomes = run_suite(translator, tasks, profile)
        table = summarize(outcomes)
        runs[name] = {
            "model": translator.model_name,
            "options": vars(translator.options),
            "wall_s": round(time.perf_counter() - started, 1),
            "table": table,
            "misses": [o.to_dict() for o in outcomes if not o.accepted],
        }
        translator.close()
        print(f"\n{name} ({translator.model_name})\n{render_table(table)}", file=sys.stderr, flush=True)
    report = {
        "note": f"nrtrans eval, {len(tasks)} tasks, one configuration after another in one run",
        "suite": args.suite or "agent/evalsuite/suite.toml",
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the end",
        "runs": runs,
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    for name, run in runs.items():
        overall = run["table"]["overall"]
        print(f"{name:28s} accuracy {overall['accuracy']:.1%}  verified {overall['success']:.1%}  "
              f"p50 {overall['latency_p50_ms']:.0f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
