"""The robot link itself: no robot at all, a robot that shuts down mid-task,
`nrtrans sim-bridge` refusing bad input, and the interfaces a robot's primitives need.
Each test owns its bridge."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from agent.backends import open_robot
from agent.robot import Outcome, Status
from agent.ros2.backend import RobotUnavailable, Ros2Robot
from agent.ros2.bridge import SimBridge
from agent.ros2.config import RosConfig
from agent.ros2.link import interfaces_needed, primitives_used
from agent.ros2.node_thread import NodeThread
from agent.sim.scene import load_scene
from agent.sim.world import SimWorld
from rsl.profile import Profile, parse_profile

from .conftest import REPO, ROS_ENV, Bridge
from .slow_announcer import SLOW_DISCOVERY

pytestmark = pytest.mark.timeout(120)


def test_no_robot_at_all_is_a_clear_error_not_a_hang(profile: Profile) -> None:
    # Topics nobody serves: the same as a robot that is off or on another domain.
    ros = {k: f"/absent{v}" for k, v in dataclasses.asdict(RosConfig()).items()
           if isinstance(v, str) and v.startswith("/")}
    config = dataclasses.replace(RosConfig.from_profile(profile), **ros)
    started = time.monotonic()
    with pytest.raises(RobotUnavailable) as error:
        open_robot("ros2", profile, config=config, connect_timeout=1.0)
    assert time.monotonic() - started < 5.0
    message = str(error.value)
    assert "no odometry arrived on /absent/odom within 1 s" in message
    assert "nrtrans sim-bridge" in message and "ROS_DOMAIN_ID" in message


def test_robot_shutting_down_mid_motion_fails_the_step_and_exits_cleanly(profile: Profile) -> None:
    bridge = Bridge(1.0)
    try:
        robot = Ros2Robot(profile, connect_timeout=30.0)
        result: list[Outcome] = []
        thread = threading.Thread(target=lambda: result.append(robot.forward(3.0)), daemon=True)
        thread.start()
        time.sleep(1.0)
        assert bridge.terminate() == 0, bridge.output()
        assert "sim-bridge: stopped" in bridge.output()
        thread.join(5.0)
        assert result and result[0].status is Status.FAILED
        assert "stale" in result[0].reason
        later = robot.turnleft(0.5)
        assert later.status is Status.FAILED and "stale" in later.reason
        robot.close()
    finally:
        bridge.kill()


@pytest.mark.parametrize(("args", "message"), [
    (["--scene", "/nonexistent/scene.toml"], "cannot read scene file /nonexistent/scene.toml"),
    (["--profile", "/nonexistent/robot.toml"], "cannot read robot profile /nonexistent/robot.toml"),
    (["--realtime-factor", "0"], "--realtime-factor must be positive"),
])
def test_sim_bridge_rejects_bad_input_with_exit_2(args: list[str], message: str) -> None:
    done = subprocess.run([sys.executable, "-m", "agent.cli", "sim-bridge", *args], cwd=REPO,
                          env={**ROS_ENV, "PATH": "/usr/bin:/bin"}, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr


def test_a_robot_that_only_grasps_is_offered_the_look_a_grasp_falls_back_on(profile: Profile) -> None:
    """Grasping an object not yet known calls the perception service first, so the simulator's bridge
    must offer it for a robot whose perceive and approach skills are bound elsewhere."""
    text = Path(profile.source).read_text(encoding="utf-8")
    for primitive, binding in [("perceive_objects", '{ ros = "trigger", service = "/look" }'),
                               ("approach_object", '{ ros = "topic", topic = "/approach", '
                                                   'type = "std_msgs/msg/String", fields = { data = "object" } }')]:
        bound = f'binding = {{ primitive = "{primitive}" }}'
        assert bound in text
        text = text.replace(bound, f"binding = {binding}")
    grasping = parse_profile(text)
    assert "perception" in interfaces_needed(primitives_used(grasping))
    assert "perception" not in interfaces_needed({"drive", "turn", "navigate"})
    scene = load_scene()
    bridge = SimBridge(grasping, lambda: SimWorld(grasping, scene), node_name="nrtrans_test_grasp_only_bridge")
    try:
        assert bridge.config.perceive_service in bridge.interfaces
        assert bridge.config.grasp_service in bridge.interfaces
    finally:
        bridge.close()


@pytest.mark.skipif(os.environ.get("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp") != "rmw_fastrtps_cpp",
                    reason="the profile that slows discovery down is Fast DDS's")
def test_a_server_that_discovers_the_caller_late_is_called_once_and_its_reply_arrives(tmp_path: Path) -> None:
    """A server that appears while a backend waits for it can accept the request before it has matched the
    backend's response reader; Fast DDS then drops the reply after 100 ms (ros2/ros2#1253), which is how
    a late /dock on a loaded machine failed now and then. Here the backend's announcements trickle out, so
    the server learns of its response reader about 0.4 s after its request writer on every run."""
    from std_srvs.srv import Trigger

    profile = tmp_path / "slow_discovery.xml"
    profile.write_text(SLOW_DISCOVERY, encoding="utf-8")
    name = "/late/slow_dock"
    caller = subprocess.Popen(
        [sys.executable, "-m", "tests.ros2.slow_announcer", name], cwd=REPO, text=True,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        env={**os.environ, **ROS_ENV, "FASTDDS_DEFAULT_PROFILES_FILE": str(profile), "PYTHONPATH": str(REPO)})
    calls: list[float] = []
    server: NodeThread | None = None
    try:
        assert caller.stdout is not None
        assert caller.stdout.readline().strip() == "calling", caller.communicate(timeout=30)[1]
        server = NodeThread("nrtrans_test_slow_dock")

        def dock(_request: object, response: object) -> object:
            calls.append(time.monotonic())
            response.success, response.message = True, "docked"  # type: ignore[attr-defined]
            return response

        server.node.create_service(Trigger, name, dock)
        out, err = caller.communicate(timeout=60)
    finally:
        if caller.poll() is None:
            caller.kill()
            caller.wait()
        if server is not None:
            server.close()
    assert caller.returncode == 0, err
    assert json.loads(out.splitlines()[-1]) == {"success": True, "message": "docked"}, err
    assert len(calls) == 1, "a request to a dock must not be repeated"
