"""Checking throughput on a 10,000-statement program, and peak memory.

Target: a 10,000-statement program checked in under 0.5 s on 2 cores.
Writes bench/results/check.json.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import random
import resource
import statistics
import time
import tracemalloc
from pathlib import Path

from rsl.compiler import compile_program
from rsl.profile import load_profile

RESULTS = Path(__file__).parent / "results"


def program(statements: int, seed: int = 7) -> str:
    rng = random.Random(seed)
    shapes = [
        lambda: f"forward {rng.uniform(0.1, 9):.2f};",
        lambda: f"turnleft {rng.uniform(0.1, 6):.4f};",
        lambda: f"lookdown {rng.uniform(0.1, 1):.3f};",
        lambda: f"goto {rng.uniform(-9, 9):.2f}, {rng.uniform(-9, 9):.2f};",
        lambda: "perceive;",
        lambda: f"grasp {rng.choice(['cup', 'ball', 'red_book'])};",
        lambda: "// a comment line",
        lambda: f"/* block */ backward {rng.uniform(0.1, 2):.1f};",
    ]
    lines: list[str] = []
    while sum(1 for line in lines if not line.startswith("//")) < statements:
        lines.append(rng.choice(shapes)())
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--statements", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()

    profile = dataclasses.replace(load_profile(), max_statements=args.statements)
    source = program(args.statements)
    compile_program(source, profile)  # warm caches and imports
    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        result = compile_program(source, profile)
        times.append(time.perf_counter() - start)
    assert result.ok and len(result.plan or ()) == args.statements

    tracemalloc.start()
    compile_program(source, profile)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()

    median = statistics.median(times)
    figures = {
        "benchmark": "check",
        "statements": args.statements,
        "source_bytes": len(source),
        "runs": args.repeat,
        "median_s": round(median, 4),
        "min_s": round(min(times), 4),
        "max_s": round(max(times), 4),
        "statements_per_s": round(args.statements / median),
        "peak_python_alloc_mb": round(peak / 2**20, 2),
        "process_max_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
        "target_s": 0.5,
        "meets_target": median < 0.5,
    }
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "check.json").write_text(json.dumps(figures, indent=2) + "\n")
    print(json.dumps(figures, indent=2))


if __name__ == "__main__":
    main()
