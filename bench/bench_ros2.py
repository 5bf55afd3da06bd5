"""ROS 2 backend benchmark: command-to-motion latency, service round trip, and the
backend's own CPU and memory, against `nrtrans sim-bridge` in another process.

    .venv/bin/python bench/bench_ros2.py [--trials 30] [--output bench/results/ros2.json]

Figures (medians and 90th percentiles) go to JSON. The bridge runs in real time
on a private ROS domain on loopback; the machine's other load is not controlled,
so compare figures only from one run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SCRATCH = tempfile.mkdtemp(prefix="nrtrans-bench-ros-")
os.environ.update({
    "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
    "ROS_DOMAIN_ID": str(100 + os.getpid() % 130),
    "ROS_LOG_DIR": SCRATCH,
})
sys.path.insert(0, str(REPO))

from agent.robot import CancelToken  # noqa: E402
from agent.ros2.backend import Ros2Robot  # noqa: E402
from rsl.profile import load_profile  # noqa: E402

MOVING = 0.005  # m/s in odometry counts as motion
SCENARIO = [("forward", (1.0,)), ("turnleft", (1.5708,)), ("lookleft", (0.5,)), ("perceive", ()),
            ("lookright", (0.5,)), ("goto", (0.0, 0.0))]


def summary(samples: list[float]) -> dict[str, float | int]:
    ordered = sorted(samples)
    return {"median_ms": round(statistics.median(ordered) * 1000, 2),
            "p90_ms": round(ordered[int(0.9 * (len(ordered) - 1))] * 1000, 2),
            "min_ms": round(ordered[0] * 1000, 2), "n": len(ordered)}


def rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def command_to_motion(robot: Ros2Robot, trials: int) -> list[float]:
    """Publish one Twist to a base at rest; time until odometry shows it moving."""
    link = robot._link
    samples = []
    for _ in range(trials):
        robot.stop()
        time.sleep(0.4)
        sent = time.monotonic()
        link.send_twist(0.3, 0.0)
        while True:
            odom = link.wait_for_odometry(2.0, newer_than=link.odometry().received)
            if odom is None:
                raise SystemExit("bench: odometry stopped; see the bridge's output")
            if odom.linear > MOVING:
                samples.append(odom.received - sent)
                break
        link.send_zero_twist()
    robot.stop()
    return samples


def service_round_trip(robot: Ros2Robot, trials: int) -> list[float]:
    samples = []
    for _ in range(trials):
        started = time.monotonic()
        robot._link.call_perceive(CancelToken())
        samples.append(time.monotonic() - started)
    return samples


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--trials", type=int, default=30, help="samples per latency figure (default 30)")
    parser.add_argument("--output", default=str(REPO / "bench" / "results" / "ros2.json"),
                        help="where the JSON goes (default bench/results/ros2.json)")
    args = parser.parse_args()

    rss_before = rss_mib()
    bridge = subprocess.Popen([sys.executable, "-m", "agent.cli", "sim-bridge"], cwd=REPO,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        connect_started = time.monotonic()
        robot = Ros2Robot(load_profile(), connect_timeout=60.0)
        connect = time.monotonic() - connect_started
        print(f"connected in {connect:.2f} s; measuring command-to-motion ({args.trials} trials)", flush=True)
        motion = command_to_motion(robot, args.trials)
        print("measuring the perceive service round trip", flush=True)
        service = service_round_trip(robot, args.trials)

        print("measuring idle CPU for 5 s", flush=True)
        cpu, wall = cpu_seconds(), time.monotonic()
        time.sleep(5.0)
        idle_cpu = (cpu_seconds() - cpu) / (time.monotonic() - wall)

        print("running a scenario for busy CPU", flush=True)
        cpu, wall = cpu_seconds(), time.monotonic()
        for skill, step_args in SCENARIO:
            outcome = getattr(robot, skill)(*step_args)
            if not outcome.ok:
                raise SystemExit(f"bench: `{skill}` {outcome.status.value}: {outcome.reason}")
        scenario_wall = time.monotonic() - wall
        busy_cpu = (cpu_seconds() - cpu) / scenario_wall
        rss_connected = rss_mib()
        robot.close()
    finally:
        bridge.send_signal(signal.SIGTERM)
        try:
            bridge.wait(timeout=15)
        except subprocess.TimeoutExpired:
            bridge.kill()
        shutil.rmtree(SCRATCH, ignore_errors=True)

    results = {
        "benchmark": "ros2",
        "what": "ROS 2 backend against nrtrans sim-bridge (separate process, real time, loopback DDS)",
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": platform.python_version(),
                    "note": "shared machine: other engineers' jobs ran at the same time"},
        "connect_s": round(connect, 3),
        "command_to_motion": {**summary(motion),
                              "definition": "Twist published on cmd_vel -> first odometry showing the base "
                                            "moving, received back in the backend; includes the bridge's "
                                            "50 Hz control tick"},
        "perceive_round_trip": {**summary(service),
                                "definition": "std_srvs/Trigger call to the perceive service and its reply"},
        "backend_cpu": {"idle_fraction_of_one_core": round(idle_cpu, 4),
                        "busy_fraction_of_one_core": round(busy_cpu, 4),
                        "busy_scenario": " ".join(f"{s} {', '.join(map(str, a))};".replace(" ;", ";")
                                                  for s, a in SCENARIO),
                        "busy_scenario_wall_s": round(scenario_wall, 2)},
        "backend_memory_mib": {"before_rclpy": round(rss_before, 1),
                               "connected_after_scenario": round(rss_connected, 1)},
    }
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    Path(args.output).write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
