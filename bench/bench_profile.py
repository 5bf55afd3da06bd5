"""Translation for a robot other than the default one: the shipped base-only profile.

The shipped LoRA adapter is trained on the default profile, so the translator
loads the base model with the shot bank for this profile (the bundled shots
that compile on it, plus its conventions). Runs the tasks of
bench/turtlebot_tasks.toml once each, after one warm-up, and reports how many
gave the expected program (canonical RSL, exact) or were refused as they
should be, with latency. Writes bench/results/profile_turtlebot.json.

    python bench/bench_profile.py [--profile rsl/profiles/turtlebot.toml] [--tasks bench/turtlebot_tasks.toml]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tomllib
from pathlib import Path

from agent.evalsuite.runner import percentile
from agent.translate import Translator
from rsl.compiler import compile_program
from rsl.profile import load_profile


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--profile", default="rsl/profiles/turtlebot.toml")
    parser.add_argument("--tasks", default="bench/turtlebot_tasks.toml")
    parser.add_argument("--out", default="bench/results/profile_turtlebot.json")
    args = parser.parse_args()

    profile = load_profile(args.profile)
    tasks = tomllib.loads(Path(args.tasks).read_text(encoding="utf-8"))["tasks"]
    translator = Translator.load(profile)
    translator.translate("turn left")  # warm-up: evaluates the fixed prompt prefix once
    rows, latencies = [], []
    for index, task in enumerate(tasks, start=1):
        result = translator.translate(task["task"], known_objects=task.get("objects"))
        latencies.append(result.timings_ms["total"])
        if task.get("refused"):
            right = not result.verified and result.passes == 0
        else:
            expected = compile_program(task["program"], profile).plan
            assert expected is not None, f"the expected program of {task['task']!r} does not compile"
            right = result.verified and result.plan is not None and result.plan.to_rsl() == expected.to_rsl()
        got = result.program if result.verified else "; ".join(
            d.message for d in (result.attempts[-1].diagnostics if result.attempts else ()))
        rows.append({"task": task["task"], "right": right, "got": got, "ms": round(result.timings_ms["total"], 1)})
        print(f"[{index}/{len(tasks)}] {'ok ' if right else 'BAD'} {result.timings_ms['total']:.0f} ms "
              f"{task['task']!r} -> {got!r}", file=sys.stderr)
    translate_ms = [r["ms"] for r, t in zip(rows, tasks, strict=True) if not t.get("refused")]
    report = {
        "profile": profile.name,
        "model": translator.model_name,
        "mode": "base model with the shot bank (the shipped adapter is for the default profile)",
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the end; "
                   "shared with other jobs",
        "tasks": len(tasks),
        "right": sum(r["right"] for r in rows),
        "refusals_expected": sum(1 for t in tasks if t.get("refused")),
        "latency_ms_translated": {"p50": round(percentile(translate_ms, 0.5), 1),
                                  "p95": round(percentile(translate_ms, 0.95), 1),
                                  "mean": round(statistics.fmean(translate_ms), 1)},
        "rows": rows,
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    print(json.dumps({k: v for k, v in report.items() if k != "rows"}, indent=2))
    translator.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
