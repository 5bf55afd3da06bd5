"""Simulator backend: physics rate, a standard program's wall and CPU time, memory, and stopping time.

Measures, with medians over --repeat runs:
- physics steps per wall second (the base driving, the head moving);
- the standard program (the shared scenarios of tests/sim/scenarios.py, run
  back to back on one robot) at realtime_factor 0: wall seconds, CPU seconds,
  simulated seconds, and how many times faster than real time;
- peak RSS of this process, and RSS after the imports, for scale;
- cancel-to-standstill at realtime_factor 1: simulated and wall seconds from
  the cancel to the base at rest (the target is 0.2 s).

Writes bench/results/sim.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from agent.executor import execute  # noqa: E402
from agent.robot import CancelToken  # noqa: E402
from agent.sim.robot import SimRobot  # noqa: E402
from agent.sim.world import PHYSICS_HZ, SimWorld  # noqa: E402
from rsl.compiler import compile_program  # noqa: E402
from rsl.profile import Profile, load_profile  # noqa: E402
from tests.sim.scenarios import SCENARIOS  # noqa: E402

RESULTS = REPO / "bench" / "results"
_BY_NAME = {s.name: s.program for s in SCENARIOS}
# The square, a look around, then fetching the cup and bringing it back: every kind of skill.
STANDARD = " ".join((_BY_NAME["square_left"], _BY_NAME["look_around"], _BY_NAME["approach_then_grasp"], "goto 0, 0;"))


def rss_mb() -> float:
    with open("/proc/self/status", encoding="utf-8") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def physics_rate(profile: Profile, steps: int) -> float:
    world = SimWorld(profile)
    try:
        world.set_base_velocity(0.4, 0.3)
        world.set_head_target(1.0, 0.3)
        started = time.perf_counter()
        world.step(steps)
        return steps / (time.perf_counter() - started)
    finally:
        world.close()


def standard_program(profile: Profile) -> dict[str, float]:
    result = compile_program(STANDARD, profile)
    assert result.ok and result.plan is not None, [d.brief() for d in result.diagnostics]
    with SimRobot(profile) as robot:
        wall, cpu = time.perf_counter(), time.process_time()
        execution = execute(result.plan, robot, profile)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        assert execution.ok, [o.reason for o in execution.outcomes]
        simulated = robot.world.sim_time
    return {"steps": len(result.plan), "wall_s": wall, "cpu_s": cpu, "sim_s": simulated,
            "x_real_time": simulated / wall}


def stopping(profile: Profile) -> dict[str, float]:
    with SimRobot(profile, realtime_factor=1.0) as robot:
        token = CancelToken()
        worker = threading.Thread(target=robot.forward, args=(5.0,), kwargs={"cancel": token})
        worker.start()
        while robot.state().pose.x < 0.6:
            time.sleep(0.002)
        cancelled = time.monotonic()
        token.set("bench")
        worker.join()
        samples = [s for s in robot.world.trajectory if s.wall_time >= cancelled]
        still = next(s for s in samples if abs(s.linear) < 0.005)
        return {"sim_s": still.sim_time - samples[0].sim_time, "wall_s": still.wall_time - cancelled}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5, help="runs per figure; medians are reported (default 5)")
    parser.add_argument("--steps", type=int, default=6000, help="physics steps per rate measurement")
    args = parser.parse_args()
    profile = load_profile()
    baseline = rss_mb()
    load = round(os.getloadavg()[0], 2)
    rates, programs, stops = [], [], []
    for run in range(1, args.repeat + 1):
        print(f"run {run}/{args.repeat}: physics rate, standard program, stopping", file=sys.stderr, flush=True)
        rates.append(physics_rate(profile, args.steps))
        programs.append(standard_program(profile))
        stops.append(stopping(profile))

    def median(rows: list[dict[str, float]], key: str) -> float:
        return round(statistics.median(r[key] for r in rows), 4)

    figures = {
        "benchmark": "sim",
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the end",
        "load_average_1min_at_start": load,
        "repeat": args.repeat,
        "physics_hz": PHYSICS_HZ,
        "standard_program_text": STANDARD,
        "physics_steps_per_wall_s": round(statistics.median(rates), 1),
        "standard_program": {
            "statements": programs[0]["steps"],
            "wall_s": median(programs, "wall_s"),
            "cpu_s": median(programs, "cpu_s"),
            "sim_s": median(programs, "sim_s"),
            "times_real_time": median(programs, "x_real_time"),
        },
        "cancel_to_standstill": {"sim_s": median(stops, "sim_s"), "wall_s": median(stops, "wall_s"),
                                 "max_wall_s": round(max(s["wall_s"] for s in stops), 4), "target_s": 0.2},
        "rss_mb_after_imports": round(baseline, 1),
        "peak_rss_mb": round(peak_rss_mb(), 1),
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "sim.json").write_text(json.dumps(figures, indent=2) + "\n", encoding="utf-8")
    print(json.dumps(figures, indent=2))


if __name__ == "__main__":
    main()
