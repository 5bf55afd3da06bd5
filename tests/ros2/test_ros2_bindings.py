"""Skills that are data all the way to the motors, over real DDS:
- a profile with every keyword renamed drives `nrtrans sim-bridge` (started with that profile)
  through `nrtrans run-program --backend ros2 --profile` to the end, the cup held;
- skills added by profile alone reach a test node with the right values: `wave` as a
  JointTrajectory on an arm joint, `dock` as a std_srvs Trigger call, `lights` as a topic publish.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from agent.executor import execute
from agent.robot import CancelToken, Status
from agent.ros2.backend import Ros2Robot
from agent.ros2.node_thread import NodeThread
from rsl.compiler import compile_program
from tests.bindings.skills import ARM_JOINT, ARM_TOPIC, DOCK_SERVICE, LIGHTS_TOPIC, extended_profile
from tests.sim.renamed import FETCH_AND_RETURN, write_renamed_profile

from .conftest import REPO, ROS_ENV, SCRATCH, Bridge, Probe


@pytest.fixture(scope="module")
def renamed_bridge() -> Iterator[tuple[Bridge, Path]]:
    """`nrtrans sim-bridge --profile renamed.toml`: the bridge too reads bindings, not keywords."""
    folder = SCRATCH / "renamed"
    folder.mkdir(exist_ok=True)
    path = write_renamed_profile(folder)
    bridge = Bridge(2.0, "--profile", str(path))
    yield bridge, path
    assert bridge.terminate() == 0, bridge.output()


class RobotSpecificDrivers:
    """The robot's own interfaces for the profile-only skills: what a real arm controller, dock
    and light ring would receive."""

    def __init__(self) -> None:
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64
        from std_srvs.srv import Trigger
        from trajectory_msgs.msg import JointTrajectory

        self._ros = NodeThread("nrtrans_test_robot_specific")
        node = self._ros.node
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self.trajectories: list[Any] = []
        self.lights: list[float] = []
        self.dock_calls = 0
        self.dock_answer = (True, "docked, charging")
        self.received = threading.Event()
        node.create_subscription(JointTrajectory, ARM_TOPIC, self._on_trajectory, reliable)
        node.create_subscription(Float64, LIGHTS_TOPIC, self._on_lights, reliable)
        node.create_service(Trigger, DOCK_SERVICE, self._on_dock)
        # Off until a test turns it on: then the arm reports its joint, as a real arm does,
        # moving to each trajectory's end point in one step.
        self.report_arm = False
        self.arm_position = 0.0
        self._joint_state = JointState
        self._joints = node.create_publisher(JointState, "/joint_states", reliable)
        node.create_timer(0.05, self._publish_arm)

    def _on_trajectory(self, msg: Any) -> None:
        self.trajectories.append(msg)
        self.arm_position = float(msg.points[-1].positions[0])
        self.received.set()

    def _publish_arm(self) -> None:
        if self.report_arm:
            self._joints.publish(self._joint_state(name=[ARM_JOINT], position=[self.arm_position]))

    def _on_lights(self, msg: Any) -> None:
        self.lights.append(msg.data)
        self.received.set()

    def _on_dock(self, _request: Any, response: Any) -> Any:
        self.dock_calls += 1
        response.success, response.message = self.dock_answer
        return response

    def close(self) -> None:
        self._ros.close()


@pytest.fixture(scope="module")
def drivers() -> Iterator[RobotSpecificDrivers]:
    node = RobotSpecificDrivers()
    yield node
    node.close()


def test_every_keyword_renamed_fetches_and_returns_over_ros2(renamed_bridge: tuple[Bridge, Path],
                                                             probe: Probe, tmp_path: Path) -> None:
    bridge, profile = renamed_bridge
    probe.reset_world()
    program = tmp_path / "fetch.rsl"
    program.write_text(FETCH_AND_RETURN, encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "agent.cli", "run-program", str(program), "--backend", "ros2",
                           "--profile", str(profile), "--json"], cwd=REPO, capture_output=True, text=True,
                          timeout=300, env={**os.environ, **ROS_ENV, "PYTHONPATH": str(REPO)})
    assert done.returncode == 0, f"{done.stderr}\n--- bridge ---\n{bridge.output()}"
    report = json.loads(done.stdout)
    assert report["status"] == "done"
    assert [s["status"] for s in report["steps"]] == ["done"] * 4
    state = report["final_state"]
    assert state["holding"] == "cup"
    assert abs(state["pose"]["x"]) < 0.05 and abs(state["pose"]["y"]) < 0.05


def test_skills_added_by_profile_alone_reach_the_robot_with_their_values(
        renamed_bridge: tuple[Bridge, Path], probe: Probe, drivers: RobotSpecificDrivers) -> None:
    profile = extended_profile()
    probe.reset_world()
    plan = compile_program("wave 0.8;\ndock;\nlights 0.5;\nforward 0.1;\n", profile).plan
    assert plan is not None
    with Ros2Robot(profile, connect_timeout=30.0) as robot:
        result = execute(plan, robot, profile, cancel=CancelToken())
    assert result.ok, [o.reason for o in result.outcomes]
    deadline = time.monotonic() + 5.0
    while not drivers.lights and time.monotonic() < deadline:
        time.sleep(0.02)
    [trajectory] = drivers.trajectories
    assert list(trajectory.joint_names) == [ARM_JOINT]
    assert list(trajectory.points[0].positions) == [pytest.approx(0.8)]
    assert trajectory.points[0].time_from_start.nanosec == 500_000_000
    assert drivers.dock_calls == 1
    assert drivers.lights == [pytest.approx(0.5)]
    wave, dock, _lights, forward = result.outcomes
    assert "arrival not checked, joint_states does not report arm_shoulder_joint" in wave.reason
    assert dock.reason == "/dock: docked, charging"
    assert forward.ok and result.final_state is not None and result.final_state.pose.x == pytest.approx(0.1, abs=0.02)


def test_a_trajectory_to_a_joint_the_robot_reports_waits_for_it_to_arrive(
        renamed_bridge: tuple[Bridge, Path], probe: Probe, drivers: RobotSpecificDrivers) -> None:
    profile = extended_profile()
    drivers.report_arm = True
    try:
        with Ros2Robot(profile, connect_timeout=30.0) as robot:
            deadline = time.monotonic() + 10.0
            while ARM_JOINT not in robot._link.joints()[0]:
                assert time.monotonic() < deadline, "the arm's joint state never arrived"
                time.sleep(0.02)
            outcome = robot.wave(1.2, cancel=CancelToken())  # type: ignore[attr-defined]
            assert robot._link.joints()[0][ARM_JOINT] == pytest.approx(1.2)
    finally:
        drivers.report_arm = False
    assert outcome.ok and outcome.reason == ""  # arrival was checked, nothing to note
    assert list(drivers.trajectories[-1].points[0].positions) == [pytest.approx(1.2)]


def test_a_service_that_refuses_fails_the_step_with_its_reason(
        renamed_bridge: tuple[Bridge, Path], probe: Probe, drivers: RobotSpecificDrivers) -> None:
    profile = extended_profile()
    drivers.dock_answer = (False, "no dock in sight")
    try:
        with Ros2Robot(profile, connect_timeout=30.0) as robot:
            outcome = robot.dock(cancel=CancelToken())  # type: ignore[attr-defined]
    finally:
        drivers.dock_answer = (True, "docked, charging")
    assert outcome.status is Status.FAILED
    assert outcome.reason == "/dock refused: no dock in sight"


def test_a_service_discovered_seconds_after_start_still_answers(
        renamed_bridge: tuple[Bridge, Path], probe: Probe) -> None:
    """On CI's two loaded cores a just-started backend once took over 2 s to discover /dock
    and failed the step; DDS discovery is that slow there, so the backend must wait for it."""
    from std_srvs.srv import Trigger

    from rsl.profile import parse_profile
    from tests.bindings.skills import profile_text

    late_name = "/late/dock"
    profile = parse_profile(profile_text().replace(f'service = "{DOCK_SERVICE}"', f'service = "{late_name}"'),
                            source="late.toml")
    late: list[NodeThread] = []

    def offer_late() -> None:
        ros = NodeThread("nrtrans_test_late_dock")
        ros.node.create_service(Trigger, late_name, lambda _req, res: _answered(res, "docked late"))
        late.append(ros)

    try:
        with Ros2Robot(profile, connect_timeout=30.0) as robot:
            timer = threading.Timer(3.0, offer_late)
            timer.start()
            outcome = robot.dock(cancel=CancelToken())  # type: ignore[attr-defined]
            timer.join()
    finally:
        for ros in late:
            ros.close()
    assert outcome.ok, outcome.reason
    assert outcome.reason == f"{late_name}: docked late"


def _answered(response: Any, message: str) -> Any:
    response.success, response.message = True, message
    return response


class Dock:
    """The base-only robot's dock services, on its own names."""

    def __init__(self) -> None:
        from std_srvs.srv import Trigger

        self._ros = NodeThread("nrtrans_test_tb4_dock")
        self.calls: list[str] = []
        for name in ("/tb4/dock", "/tb4/undock"):
            self._ros.node.create_service(Trigger, name, lambda _req, res, name=name: self._answer(name, res))

    def _answer(self, name: str, response: Any) -> Any:
        self.calls.append(name)
        response.success, response.message = True, ""
        return response

    def close(self) -> None:
        self._ros.close()


def test_the_base_only_profile_runs_over_its_own_ros_names(probe: Probe) -> None:
    from rsl.profile import load_profile

    path = REPO / "rsl" / "profiles" / "turtlebot.toml"
    turtlebot = load_profile(path)
    bridge = Bridge(2.0, "--profile", str(path))
    dock = Dock()
    try:
        plan = compile_program("undock; forward 0.5; turnleft 1.5708; goto 0, 0; dock;", turtlebot).plan
        assert plan is not None
        with Ros2Robot(turtlebot, connect_timeout=30.0) as robot:
            result = execute(plan, robot, turtlebot, cancel=CancelToken())
        assert result.ok, [o.reason for o in result.outcomes]
        assert dock.calls == ["/tb4/undock", "/tb4/dock"]
        assert result.final_state is not None and abs(result.final_state.pose.x) < 0.05
        assert probe.node.count_publishers("/tb4/odom") == 1
    finally:
        dock.close()
        status = bridge.terminate()
    assert status == 0, bridge.output()
    assert "sim-bridge: serving /tb4/cmd_vel, /tb4/odom" in bridge.output()
    # It has no head and no gripper, so the bridge offers neither.
    assert "/head_controller" not in bridge.output() and "/grasp" not in bridge.output()
