"""`nrtrans eval` side by side: base model with shots vs the RSL adapter, each with and without the grammar.

Runs the whole evaluation suite four times in one process, one configuration
after another, on the same machine state, and writes per-group accuracy,
success (verified), mean passes and latency for each, plus the tasks each got
wrong. Writes bench/results/eval_side_by_side.json.

    python bench/bench_eval.py [--adapter PATH|default] [--suite FILE] [--every K] [--out FILE]

With --compare ADAPTER ... it instead runs the default configuration
(adapter, grammar) with each adapter in turn (old against new, or a training
run's checkpoints for a learning curve) on the evaluation suite, the novel
tasks and the fresh development set, and writes
bench/results/eval_adapters.json. Only the suite's and the novel set's
per-task results are kept: of the fresh sets, and of any other suite file
named in --sets, only the per-group table may be looked at. An adapter
trained on an older prompt format is refused by the runtime; pass a copy of
its GGUF without the card to compare it anyway.

    python bench/bench_eval.py --compare /tmp/old.gguf models/adapters/rsl-default-gemma3-270m-q4km.gguf
    python bench/bench_eval.py --compare run.step200.gguf run.step400.gguf run.gguf --sets suite,dev
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

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from agent.evalsuite import load_suite
from agent.evalsuite.runner import render_table, run_suite, summarize
from agent.translate import Translator
from bench import SPLIT
from rsl.profile import load_profile

SETS = {"suite": None, "novel": "bench/novel_tasks.toml", "dev": "bench/fresh/dev.toml",
        "final": "bench/fresh/final.toml"}
# Only these sets' per-task results may be read; of any other (the fresh sets, a held-out file) only the
# per-group table is kept.
READABLE = ("suite", "novel")

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
    parser.add_argument("--out", help="JSON report (default: bench/results/eval_side_by_side.json, or "
                                      "bench/results/eval_adapters.json with --compare)")
    parser.add_argument("--compare", nargs="+", metavar="ADAPTER",
                        help="two or more adapters (old, new, or a training run's checkpoints for a learning "
                             "curve), each run with the defaults on the suite, novel and dev sets")
    parser.add_argument("--sets", default="suite,novel,dev",
                        help=f"with --compare: which of {', '.join(SETS)} to run, or a suite file's path, whose "
                             "per-task results are not kept (default: suite,novel,dev)")
    parser.add_argument("--split", choices=tuple(SPLIT), default="default",
                        help="with --compare: clause splitting (default: the translator's default)")
    args = parser.parse_args()
    if args.compare:
        split = SPLIT[args.split]
        return compare(args.compare, [s.strip() for s in args.sets.split(",") if s.strip()], args.every,
                       split, args.out or "bench/results/eval_adapters.json")
    args.out = args.out or "bench/results/eval_side_by_side.json"

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


def compare(adapters: list[str], sets: list[str], every: int, split: bool | None, out: str) -> int:
    unknown = [name for name in sets if name not in SETS and not Path(name).is_file()]
    if unknown:
        print(f"bench_eval: error: unknown set {', '.join(unknown)}; choose from {', '.join(SETS)} or name a "
              "suite file", file=sys.stderr)
        return 2
    profile = load_profile()
    results: dict[str, dict[str, Any]] = {}
    for adapter in adapters:
        translator = Translator.load(profile, adapter=adapter, split_clauses=split)
        for name in sets:
            path = SETS.get(name, name)
            tasks = list(load_suite(path, profile=profile))[:: max(1, every)]
            started = time.perf_counter()
            outcomes = run_suite(translator, tasks, profile)
            table = summarize(outcomes)
            entry: dict[str, Any] = {"suite": path or "agent/evalsuite/suite.toml", "tasks": len(tasks),
                                     "wall_s": round(time.perf_counter() - started, 1), "table": table}
            if name in READABLE:
                entry["misses"] = [o.to_dict() for o in outcomes if not o.accepted]
            results.setdefault(name, {})[adapter] = entry
            print(f"\n{name}, adapter {adapter}\n{render_table(table)}", file=sys.stderr, flush=True)
        translator.close()
    report = {
        "note": f"grammar on, clause splitting {({None: 'default', True: 'on', False: 'off'})[split]}, "
                f"every {every}. task",
        "adapters": adapters,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the end",
        "sets": results,
    }
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    for name, by_adapter in results.items():
        for adapter, entry in by_adapter.items():
            overall = entry["table"]["overall"]
            print(f"{name:6s} {adapter:60s} accuracy {overall['accuracy']:.1%}  "
                  f"p50 {overall['latency_p50_ms']:.0f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
