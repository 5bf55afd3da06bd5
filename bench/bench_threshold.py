"""Where to ask: wrong programs run unasked and right programs questioned at each confidence threshold.

Reads the JSON files `bench_confidence.py --out` wrote (one per set), sums
their coverage curves and reports, for each threshold on the grid, how many
wrong programs would run unasked and how many right programs would be
questioned if the default policy asked below it; then the lowest threshold
that meets both targets (--unasked-per-100, --questioned-percent). Run
bench_confidence on each set first, for example:

    for s in dev final final2; do
      python bench/bench_confidence.py --suite bench/fresh/$s.toml --out /tmp/conf/$s.json
    done
    python bench/bench_threshold.py /tmp/conf/*.json

Writes bench/results/unsure_threshold.json (or --out).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"


def at_thresholds(reports: list[dict]) -> list[dict[str, float]]:
    """Summed over the sets: programs run, wrong ones run unasked and right ones questioned per threshold."""
    rows: dict[float, dict[str, float]] = {}
    for report in reports:
        programs = report["right_programs"] + report["wrong_programs"]
        for point in report["coverage_curve"]:
            kept = point["coverage"] * programs
            wrong = kept * (1 - (point["accuracy"] or 0.0))
            row = rows.setdefault(point["threshold"], {"threshold": point["threshold"], "run_unasked": 0.0,
                                                       "right_questioned": 0.0})
            row["run_unasked"] += wrong
            row["right_questioned"] += report["right_programs"] - (kept - wrong)
    return [{k: round(v, 3) if k == "threshold" else round(v) for k, v in row.items()}
            for _, row in sorted(rows.items())]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("reports", nargs="+", type=Path, help="bench_confidence.py --out files, one per set")
    parser.add_argument("--unasked-per-100", type=float, default=2.0, help="target: wrong programs run unasked")
    parser.add_argument("--questioned-percent", type=float, default=10.0, help="target: right programs questioned")
    parser.add_argument("--out", type=Path, default=RESULTS / "unsure_threshold.json")
    args = parser.parse_args()
    try:
        reports = [json.loads(path.read_text(encoding="utf-8")) for path in args.reports]
    except (OSError, json.JSONDecodeError) as exc:
        sys.exit(f"error: cannot read a bench_confidence report: {exc}")
    items = sum(r["items"] for r in reports)
    right = sum(r["right_programs"] for r in reports)
    rows = at_thresholds(reports)
    for row in rows:
        row["run_unasked_per_100"] = round(100 * row["run_unasked"] / items, 2)
        row["right_questioned_percent"] = round(100 * row["right_questioned"] / right, 1)
    meets = [r["threshold"] for r in rows if r["run_unasked_per_100"] <= args.unasked_per_100
             and r["right_questioned_percent"] <= args.questioned_percent]
    report = {
        "what": "the confirm threshold from bench_confidence coverage curves, summed over the given sets",
        "sets": [r["suite"] for r in reports], "items": items, "right_programs": right,
        "targets": {"run_unasked_per_100": args.unasked_per_100, "right_questioned_percent": args.questioned_percent},
        "lowest_meeting_both": meets[0] if meets else None,
        "thresholds": rows,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")
    for row in rows:
        print(f"{row['threshold']:>5}: run unasked {row['run_unasked']:>4} ({row['run_unasked_per_100']}/100), "
              f"right questioned {row['right_questioned']:>4} ({row['right_questioned_percent']} %)")
    print(f"lowest meeting both targets: {report['lowest_meeting_both']} -> {args.out}")


if __name__ == "__main__":
    main()
