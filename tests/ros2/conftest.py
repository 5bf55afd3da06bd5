"""Fixtures for the ROS 2 tests: a private DDS domain on loopback, the simulator
bridge as a separate `nrtrans sim-bridge` process, and a probe node that sees
what goes over the wire (every Twist on cmd_vel, every odometry message).
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy", reason="ROS 2 wheels are not installed (pip install 'nrtrans[ros]')")

REPO = Path(__file__).resolve().parents[2]

# Every ROS participant of this test process, and the bridges it starts, live in
# one domain that no other test run on this machine uses, on loopback only.
SCRATCH = Path(tempfile.mkdtemp(prefix="nrtrans-ros-tests-"))
ROS_ENV = {
    "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
    "ROS_DOMAIN_ID": str(100 + os.getpid() % 130),
    "ROS_LOG_DIR": str(SCRATCH / "ros-log"),
}
os.environ.update(ROS_ENV)

from agent.ros2.backend import Ros2Robot  # noqa: E402
from agent.ros2.bridge import RESET_SERVICE  # noqa: E402
from agent.ros2.node_thread import NodeThread  # noqa: E402
from rsl.profile import Profile  # noqa: E402


@dataclass(frozen=True)
class TwistSample:
    at: float  # time.time() when the probe received it
    linear: float
    angular: float


@dataclass(frozen=True)
class OdomSample:
    # time.time() when the robot measured it (the message stamp), so a busy test
    # process that reads it late does not make the robot look slow.
    at: float
    x: float
    y: float
    linear: float
    angular: float


class Probe:
    """A bystander node: records cmd_vel and odom traffic and resets the simulator."""

    def __init__(self) -> None:
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from std_msgs.msg import String
        from std_srvs.srv import Trigger

        self._ros = NodeThread("nrtrans_test_probe")
        node = self._ros.node
        self.twists: list[TwistSample] = []
        self.odoms: list[OdomSample] = []
        reliable = QoSProfile(depth=50, reliability=ReliabilityPolicy.RELIABLE)
        node.create_subscription(Twist, "/cmd_vel", self._on_twist, reliable)
        node.create_subscription(Odometry, "/odom", self._on_odom, reliable)
        self._reset = node.create_client(Trigger, RESET_SERVICE)
        self._trigger = Trigger.Request
        self._string = String
        self.node = node

    def _on_twist(self, msg: Any) -> None:
        self.twists.append(TwistSample(time.time(), msg.linear.x, msg.angular.z))

    def _on_odom(self, msg: Any) -> None:
        p, t = msg.pose.pose.position, msg.twist.twist
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        self.odoms.append(OdomSample(stamp, p.x, p.y, t.linear.x, t.angular.z))

    def wait_for_publisher(self, topic: str, timeout: float = 20.0) -> None:
        """Discovery is per pair of participants: the probe sees a new backend's
        commands only once it has discovered that backend itself."""
        deadline = time.monotonic() + timeout
        while self.node.count_publishers(topic) == 0:
            assert time.monotonic() < deadline, f"the probe never discovered a publisher on {topic}"
            time.sleep(0.02)

    def publisher(self, msg_type: Any, topic: str) -> Any:
        return self.node.create_publisher(msg_type, topic, 10)

    def reset_world(self) -> None:
        assert self._reset.wait_for_service(timeout_sec=20.0), f"{RESET_SERVICE} never appeared"
        future = self._reset.call_async(self._trigger())
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        assert done.wait(20.0), "the bridge did not answer the reset"
        assert future.result().success
        self.twists.clear()
        self.odoms.clear()

    def close(self) -> None:
        self._ros.close()


class Bridge:
    """`nrtrans sim-bridge` in its own process."""

    def __init__(self, realtime_factor: float = 1.0, *extra: str) -> None:
        self.log = Path(tempfile.mkdtemp(prefix="sim-bridge-", dir=SCRATCH)) / "bridge.log"
        with self.log.open("wb") as log:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "agent.cli", "sim-bridge", "--realtime-factor", str(realtime_factor),
                 *extra],
                cwd=REPO, env={**os.environ, **ROS_ENV}, stdout=log, stderr=subprocess.STDOUT,
            )

    def output(self) -> str:
        return self.log.read_text(errors="replace")

    def terminate(self) -> int:
        """SIGTERM, as systemd sends it; returns the exit status."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGCONT)
            self.process.terminate()
            try:
                self.process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
                return -9
        return self.process.returncode

    def kill(self) -> None:
        self.process.kill()
        self.process.wait()


@pytest.fixture(scope="session", autouse=True)
def scratch_cleanup() -> Iterator[None]:
    yield
    shutil.rmtree(SCRATCH, ignore_errors=True)


@pytest.fixture(scope="module", autouse=True)
def ros_environment() -> None:
    """Re-assert the private domain before each module's nodes start, in case another
    test area changed the environment since this file was imported."""
    os.environ.update(ROS_ENV)


@pytest.fixture(scope="module")
def probe() -> Iterator[Probe]:
    probe = Probe()
    yield probe
    probe.close()


@pytest.fixture(scope="module")
def bridge(request: pytest.FixtureRequest) -> Iterator[Bridge]:
    factor = getattr(request.module, "REALTIME_FACTOR", 1.0)
    bridge = Bridge(factor)
    yield bridge
    status = bridge.terminate()
    assert status == 0, f"sim-bridge exited {status} on SIGTERM:\n{bridge.output()}"
    assert "sim-bridge: stopped" in bridge.output()


@pytest.fixture
def robot(bridge: Bridge, probe: Probe, profile: Profile) -> Iterator[Ros2Robot]:
    """A fresh backend on a freshly reset world: the robot at the origin, nothing held."""
    probe.reset_world()
    robot = Ros2Robot(profile, connect_timeout=30.0)
    probe.wait_for_publisher("/cmd_vel")
    # The probe must be matched to the backend's cmd_vel, or it misses the first commands.
    deadline = time.monotonic() + 20.0
    while robot._link.listeners("cmd_vel") < 2:
        assert time.monotonic() < deadline, "the probe never matched the backend's cmd_vel"
        time.sleep(0.02)
    yield robot
    robot.close()
    assert bridge.process.poll() is None or bridge.process.returncode == 0, bridge.output()
