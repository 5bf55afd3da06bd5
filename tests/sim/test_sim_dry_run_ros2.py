"""`run-program --backend ros2 --dry-run`: the simulator first, then the robot over real DDS.

The robot here is `nrtrans sim-bridge` in its own process, on a private ROS
domain on loopback, so the whole path a user takes is exercised.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip("rclpy", reason="ROS 2 wheels are not installed (pip install 'nrtrans[ros]')")

REPO = Path(__file__).resolve().parents[2]
NRTRANS = [sys.executable, "-m", "agent.cli"]


@pytest.fixture(scope="module")
def ros_env() -> dict[str, str]:
    scratch = tempfile.mkdtemp(prefix="nrtrans-sim-ros-")
    return {**os.environ, "PYTHONPATH": str(REPO), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
            # A domain no other test area uses at the same time (the ROS 2 tests take 100..229).
            "ROS_DOMAIN_ID": str(230 + os.getpid() % 3), "ROS_LOG_DIR": str(Path(scratch) / "ros-log")}


@pytest.fixture(scope="module")
def bridge(ros_env: dict[str, str]) -> Iterator[subprocess.Popen]:
    with tempfile.TemporaryFile() as log:
        process = subprocess.Popen([*NRTRANS, "sim-bridge", "--realtime-factor", "3"], cwd=REPO, env=ros_env,
                                   stdout=log, stderr=subprocess.STDOUT)
        yield process
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def test_dry_run_passes_then_the_robot_runs_the_program(bridge, ros_env, tmp_path: Path) -> None:
    (tmp_path / "task.rsl").write_text("perceive;\napproach table;\ngrasp cup;\nbackward 0.5;\n", encoding="utf-8")
    done = subprocess.run([*NRTRANS, "run-program", "task.rsl", "--backend", "ros2", "--dry-run", "--json"],
                          cwd=tmp_path, env=ros_env, capture_output=True, text=True, timeout=240)
    assert bridge.poll() is None, "the bridge died"
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["dry_run"]["status"] == "done" and report["status"] == "done"
    assert [s["status"] for s in report["steps"]] == ["done"] * 4
    state = report["final_state"]
    assert state["holding"] == "cup"
    assert state["pose"]["x"] == pytest.approx(1.6, abs=0.05)
    assert "dry run passed; running on ros2" in done.stderr
