"""Latency from text to verified program with the model loaded, and what KV prefix reuse saves.

Translates suite tasks (one pass over --tasks of them, after one warm-up
request) and reports p50/p95 of the whole loop; then, side by side on the
same tasks, the prompt time of a request whose fixed prefix is cached vs one
whose cache was cleared first. Writes bench/results/translate.json.

    python bench/bench_translate.py [--model PATH] [--adapter PATH|none] [--tasks 40]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
from pathlib import Path

from agent.evalsuite import load_suite
from agent.evalsuite.runner import percentile
from agent.normalize import normalize_task
from agent.translate import Translator
from rsl.profile import load_profile


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--model", help="GGUF model (default: the embedded Gemma 3 270M)")
    parser.add_argument("--adapter", help="LoRA adapter GGUF, or none for the base model with shots "
                                          "(default: the shipped adapter, as the runtime loads it)")
    parser.add_argument("--tasks", type=int, default=40)
    parser.add_argument("--out", default="bench/results/translate.json")
    args = parser.parse_args()

    profile = load_profile()
    translator = Translator.load(profile, model=args.model, adapter=args.adapter)
    suite = load_suite(profile=profile)
    # Every 2nd task across all groups, so the sample mixes short and long tasks.
    tasks = list(suite[::2])[: args.tasks]
    translator.translate("turn left")  # warm-up: evaluates the fixed prompt prefix once
    latencies, verified, passes = [], 0, []
    for index, task in enumerate(tasks, start=1):
        result = translator.translate(task.task, known_objects=task.objects)
        latencies.append(result.timings_ms["total"])
        verified += result.verified
        passes.append(result.passes)
        print(f"[{index}/{len(tasks)}] {result.timings_ms['total']:.0f} ms {task.task!r}", file=sys.stderr)

    engine = translator.engine
    llm = getattr(engine, "llm", None)
    warm, cold = [], []
    for task in tasks[:10]:
        prompt = translator.prompt_for(normalize_task(task.task))
        engine.generate(prompt, None, 1)
        warm.append(engine.generate(prompt + " ", None, 1).prompt_ms)
        if llm is not None:
            llm.n_tokens = 0  # forget the cached prefix: the whole prompt is evaluated again
        cold.append(engine.generate(prompt, None, 1).prompt_ms)
    report = {
        "model": translator.model_name,
        "options": vars(translator.options),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the end",
        "tasks": len(tasks),
        "verified": verified,
        "mean_passes": statistics.fmean(passes),
        "latency_ms": {"p50": round(percentile(latencies, 0.5), 1), "p95": round(percentile(latencies, 0.95), 1),
                       "mean": round(statistics.fmean(latencies), 1)},
        "prompt_ms": {"with_prefix_reuse_median": round(statistics.median(warm), 1),
                      "without_reuse_median": round(statistics.median(cold), 1)},
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    print(json.dumps(report, indent=2))
    translator.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
