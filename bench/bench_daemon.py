"""Daemon benchmark: start to READY=1, submit to first robot command, RSS, estop latency.

Runs the real `nrtrans serve` (embedded model, simulator) in a subprocess
and talks to it over its socket, as a client would. Writes medians and all
samples to bench/results/daemon.json.

    .venv/bin/python bench/bench_daemon.py [--starts 3] [--tasks 6] [--estops 10]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from agent.client import Client  # noqa: E402

NRTRANS = str(Path(sys.executable).with_name("nrtrans"))
# Phrasings unlike any one test; the first command is what is timed, not correctness.
TASKS = [
    "move forward one meter then turn left",
    "turn right a little",
    "look up",
    "go back half a meter",
    "drive forward two meters and look left",
    "turn around",
    "move ahead 30 centimeters",
    "look down a bit then turn left 45 degrees",
]
TARGETS = {
    "start_to_ready_s": 5.0,
    "submit_to_first_command_p50_s": 1.0,
    "rss_mb": 700.0,
    "estop_to_zero_velocity_ms": 50.0,
}


class Daemon:
    def __init__(self, workdir: Path, realtime_factor: float, backend: str = "sim") -> None:
        self.workdir = workdir
        workdir.mkdir(parents=True, exist_ok=True)
        self.socket = workdir / "api.sock"
        self.config = workdir / "config.toml"
        self.config.write_text(
            f'state_dir = "{workdir / "state"}"\nlog_level = "warning"\n'
            f'[api]\nsocket = "{self.socket}"\n[robot]\nrealtime_factor = {realtime_factor}\n'
            f'backend = "{backend}"\n'
            "[speech]\nenabled = false\n"
        )
        self.process: subprocess.Popen[bytes] | None = None

    def start(self) -> float:
        """Seconds from spawning the process to READY=1 on our notify socket."""
        notify_path = self.workdir / "notify"
        notify_path.unlink(missing_ok=True)
        notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        notify.bind(str(notify_path))
        notify.settimeout(300)
        env = {**os.environ, "NOTIFY_SOCKET": str(notify_path)}
        started = time.monotonic()
        with open(self.workdir / "log", "ab") as log:
            self.process = subprocess.Popen(
                [NRTRANS, "serve", "--config", str(self.config)], env=env, stdout=subprocess.DEVNULL, stderr=log
            )
        try:
            while b"READY=1" not in notify.recv(65536).split(b"\n"):
                pass
        finally:
            notify.close()
        return time.monotonic() - started

    def rss_mb(self) -> float:
        assert self.process is not None
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
        raise RuntimeError("no VmRSS")

    def stop(self) -> int:
        assert self.process is not None
        self.process.send_signal(signal.SIGTERM)
        return self.process.wait(120)


def median(values: list[float]) -> float:
    return statistics.median(values) if values else float("nan")


def bench_starts(workdir: Path, count: int) -> list[float]:
    times = []
    for index in range(count):
        daemon = Daemon(workdir / f"start{index}", 0.0)
        times.append(daemon.start())
        daemon.stop()
        print(f"  start {index + 1}/{count}: READY=1 after {times[-1]:.2f} s", flush=True)
    return times


def wait_warm(daemon: Daemon) -> float | None:
    """The daemon's warm-up translation time, once it has finished (as a person would find it)."""
    with Client.connect(daemon.socket, timeout=600) as client:
        deadline = time.monotonic() + 600
        while time.monotonic() < deadline:
            warm = client.health()["components"]["translator"].get("warm_s")
            if warm is not None:
                return float(warm)
            time.sleep(0.5)
    return None


def bench_tasks(daemon: Daemon, count: int) -> tuple[list[float], list[dict[str, Any]]]:
    firsts, records = [], []
    with Client.connect(daemon.socket, timeout=600) as client:
        for index, text in enumerate((TASKS * ((count // len(TASKS)) + 1))[:count]):
            sent = time.monotonic()
            task = client.submit(text=text, follow=True)
            first = None
            last = None
            for event in client.follow(task):
                if event["event"] == "executing" and first is None:
                    first = time.monotonic() - sent
                last = event
            record = client.status(task)
            records.append(
                {
                    "task": text,
                    "final": last["event"] if last else None,
                    "program": record["program"],
                    "first_command_s": first,
                    "timings_ms": record["timings_ms"],
                }
            )
            if first is not None:
                firsts.append(first)
            shown = f"{first:.2f} s" if first is not None else "never (no verified program)"
            print(f"  task {index + 1}/{count} {text!r}: first command after {shown}", flush=True)
    return firsts, records


def _start_moving(client: Client, settle: float) -> str:
    """Submit a long drive and return its id once the robot has been moving for `settle` seconds."""
    task = client.submit(rsl="forward 3;", follow=True)
    for event in client.events():
        if event["event"] == "executing" and event["task"] == task:
            break
    time.sleep(settle)
    return task


def bench_estop(daemon: Daemon, count: int) -> list[float]:
    """Client-side time from sending `estop` to its reply; the daemon replies after robot.stop() returns."""
    times = []
    with Client.connect(daemon.socket, timeout=60) as client, Client.connect(daemon.socket, timeout=60) as operator:
        for _ in range(count):
            task = _start_moving(client, settle=0.3)
            sent = time.perf_counter()
            operator.estop("benchmark")
            times.append((time.perf_counter() - sent) * 1000)
            list(client.follow(task))
            operator.reset()
            list(client.follow(client.submit(rsl="backward 0.3;", follow=True)))
    return times


def bench_estop_ros2(workdir: Path, count: int) -> list[float]:
    """Daemon on the ROS 2 backend against `nrtrans sim-bridge`: estop sent -> zero Twist seen on cmd_vel.

    The subscriber runs in this process over loopback DDS, so the figure includes one DDS hop (~0.3 ms).
    """
    os.environ.update(
        {
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
            "ROS_DOMAIN_ID": str(100 + os.getpid() % 130),
            "ROS_LOG_DIR": str(workdir / "ros-log"),
        }
    )
    import threading

    import rclpy
    from geometry_msgs.msg import Twist
    from rclpy.executors import SingleThreadedExecutor

    from rsl.profile import load_profile

    topic = load_profile().ros["cmd_vel"]
    zero_at: list[float] = []
    lock = threading.Lock()

    def on_twist(msg: Twist) -> None:
        if msg.linear.x == 0.0 and msg.angular.z == 0.0:
            with lock:
                zero_at.append(time.perf_counter())

    bridge = subprocess.Popen([NRTRANS, "sim-bridge"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rclpy.init()
    node = rclpy.create_node("bench_daemon_estop")
    node.create_subscription(Twist, topic, on_twist, 50)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    daemon = Daemon(workdir / "ros2", 1.0, backend="ros2")
    times = []
    try:
        daemon.start()
        with Client.connect(daemon.socket, timeout=60) as client, Client.connect(daemon.socket, timeout=60) as operator:
            for _ in range(count):
                task = _start_moving(client, settle=0.5)
                sent = time.perf_counter()
                operator.estop("benchmark")
                deadline = time.monotonic() + 2.0
                while time.monotonic() < deadline:
                    with lock:
                        after = [t for t in zero_at if t >= sent]
                    if after:
                        times.append((after[0] - sent) * 1000)
                        break
                    time.sleep(0.001)
                list(client.follow(task))
                operator.reset()
                list(client.follow(client.submit(rsl="backward 0.5;", follow=True)))
    finally:
        if daemon.process is not None:
            daemon.stop()
        executor.shutdown()
        node.destroy_node()
        rclpy.shutdown()
        bridge.send_signal(signal.SIGTERM)
        bridge.wait(30)
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--starts", type=int, default=3, help="daemon starts to time (default 3)")
    parser.add_argument("--tasks", type=int, default=6, help="text tasks to time (default 6)")
    parser.add_argument("--estops", type=int, default=10, help="emergency stops to time (default 10)")
    parser.add_argument(
        "--ros2",
        action="store_true",
        help="also time estop -> zero Twist on cmd_vel with the ROS 2 backend and sim-bridge",
    )
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" / "daemon.json")
    args = parser.parse_args()

    workdir = Path(tempfile.mkdtemp(prefix="nrbench-", dir="/tmp"))
    try:
        print("start to READY=1 ...", flush=True)
        starts = bench_starts(workdir, args.starts)
        main_daemon = Daemon(workdir / "main", 1.0)
        main_daemon.start()
        rss_ready = main_daemon.rss_mb()
        warm_s = wait_warm(main_daemon)
        print(f"  translator warm-up after READY took {warm_s} s", flush=True)
        print("submit to first robot command (embedded model) ...", flush=True)
        firsts, records = bench_tasks(main_daemon, args.tasks)
        rss_after = main_daemon.rss_mb()
        print("estop to zero velocity ...", flush=True)
        estops = bench_estop(main_daemon, args.estops)
        main_daemon.stop()
        estops_ros2: list[float] = []
        if args.ros2:
            print("estop to zero Twist on cmd_vel (ROS 2 backend, sim-bridge) ...", flush=True)
            estops_ros2 = bench_estop_ros2(workdir, args.estops)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)

    results = {
        "benchmark": "daemon",
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "python": platform.python_version(),
            "load_average_at_end": round(os.getloadavg()[0], 2),
        },
        "medians": {
            "start_to_ready_s": round(median(starts), 3),
            "submit_to_first_command_p50_s": round(median(firsts), 3),
            "warmup_after_ready_s": warm_s,
            "rss_mb_ready": round(rss_ready, 1),
            "rss_mb_after_tasks": round(rss_after, 1),
            "estop_to_zero_velocity_ms": round(median(estops), 3),
            "estop_to_zero_twist_ros2_ms": round(median(estops_ros2), 3) if estops_ros2 else None,
        },
        "targets": TARGETS,
        "samples": {
            "start_to_ready_s": starts,
            "submit_to_first_command_s": firsts,
            "estop_ms": estops,
            "estop_ros2_ms": estops_ros2,
        },
        "tasks": records,
        "method": {
            "start_to_ready_s": "spawn of `nrtrans serve` to READY=1 on a notify socket owned by the benchmark",
            "submit_to_first_command": "client sends submit(text) to the `executing` event of step 1 "
            "(sent just before the first command goes to the robot)",
            "rss": "VmRSS of the daemon after READY=1 (model, profile, simulator loaded) and after the tasks",
            "estop": "client sends estop to its reply, which the daemon sends after robot.stop() has "
            "commanded zero velocity",
        },
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results["medians"], indent=2))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
