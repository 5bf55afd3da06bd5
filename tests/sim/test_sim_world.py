"""Scene files and the physics world underneath the skills."""

from __future__ import annotations

import math
import time

import pytest

from agent.backends import BackendError, open_robot
from agent.robot import Robot
from agent.sim.robot import SimRobot
from agent.sim.scene import SceneError, load_scene, parse_scene
from agent.sim.world import BASE_SIZE, SimWorld
from rsl.profile import Profile


def test_default_scene_has_the_named_objects() -> None:
    scene = load_scene()
    for name in ("table", "cup", "bottle", "door", "ball", "book", "banana", "tool", "workbench", "chair"):
        assert scene.object(name) is not None, name
    assert scene.object("cup").graspable and not scene.object("table").graspable


@pytest.mark.parametrize(("text", "message"), [
    ("[[objects]]\nname = 'Big Cup'\nx = 1\ny = 1\n", "must be an identifier"),
    ("[[objects]]\nname = 'cup'\nx = 1\n", r"objects\[1\]\.y must be given: .*every object needs x and y"),
    ("[[objects]]\nname = 'cup'\nx = 1\ny = 0\nshape = 'cone'\n",
     r"objects\[1\]\.shape = 'cone' is not one of 'box', 'cylinder', 'sphere'"),
    ("[[objects]]\nname = 'cup'\nx = 1\ny = 0\nsize = [0, 1, 1]\n",
     r"objects\[1\]\.size = \[0, 1, 1\]: 0\.0 is not above"),
    ("[[objects]]\nname = 'cup'\nx = 1\ny = 0\nsize = [1, 1]\n", r"objects\[1\]\.size must have 3 items"),
    ("[[objects]]\nname = 'cup'\nx = 1\ny = 0\ncolour = [1, 0, 0]\n",
     r"unknown setting objects\[1\]\.colour\n  = help: the settings here are objects\[1\]\.name, "),
    ("[start]\nx = 'near'\n", r"test\.toml: start\.x must be a number, not 'near'"),
    ("[[objects]]\nname = 'a'\nx = 1\ny = 0\n[[objects]]\nname = 'a'\nx = 2\ny = 0\n", "declared twice"),
    ("[start\n", "not valid TOML"),
])
def test_bad_scene_files_say_what_to_fix(text: str, message: str) -> None:
    with pytest.raises(SceneError, match=message):
        parse_scene(text, "test.toml")


def test_missing_scene_file_has_a_hint(tmp_path) -> None:
    with pytest.raises(SceneError, match=r"(?s)cannot read scene file .*hint"):
        load_scene(tmp_path / "missing.toml")


def test_objects_rest_where_the_scene_puts_them(profile: Profile) -> None:
    world = SimWorld(profile)
    try:
        world.step(240)
        positions = world.objects()
        for obj in world.scene.objects:
            assert math.dist(positions[obj.name][:2], (obj.x, obj.y)) < 0.01, obj.name
        assert positions["cup"][2] == pytest.approx(0.81, abs=0.01)  # on the table, not through it
    finally:
        world.close()


def test_a_hidden_object_is_not_visible(profile: Profile) -> None:
    scene = parse_scene("""
[[objects]]
name = "screen"
kind = "fixed"
x = 1.5
y = 0.0
size = [0.1, 2.0, 2.5]
[[objects]]
name = "ball"
shape = "sphere"
x = 3.0
y = 0.0
z = 1.0
size = [0.2, 0.2, 0.2]
""", "hidden")
    world = SimWorld(profile, scene)
    try:
        assert set(world.visible_objects()) == {"screen"}
    finally:
        world.close()


def test_realtime_factor_paces_the_physics(profile: Profile) -> None:
    world = SimWorld(profile, realtime_factor=2.0)
    try:
        started = time.monotonic()
        world.step(int(1.0 / world.dt))  # one simulated second
        assert 0.45 < time.monotonic() - started < 1.0
    finally:
        world.close()


def test_open_robot_gives_the_simulator_and_rejects_unknown_backends(profile: Profile, tmp_path) -> None:
    scene = tmp_path / "one.toml"
    scene.write_text("[start]\nx = 1.0\ny = 2.0\nheading = 0.5\n", encoding="utf-8")
    robot = open_robot("sim", profile, scene=scene)
    try:
        assert isinstance(robot, SimRobot) and isinstance(robot, Robot)
        pose = robot.state().pose
        assert (pose.x, pose.y, pose.heading) == pytest.approx((1.0, 2.0, 0.5), abs=1e-3)
    finally:
        robot.close()
    with pytest.raises(BackendError, match="unknown backend 'gazebo'"):
        open_robot("gazebo", profile)
    with pytest.raises(BackendError, match="takes no option"):
        open_robot("sim", profile, node_name="x")


def test_driving_into_the_table_stops_at_it_and_names_it(profile: Profile) -> None:
    # Issue 13: `forward 5;` facing the 25 kg table used to shove it 2.64 m and fail only by timeout.
    with SimRobot(profile) as robot:
        table = robot.world.scene.object("table")
        near_face = table.x - table.size[0] / 2
        outcome = robot.forward(5.0)
        assert not outcome.ok
        assert outcome.reason.startswith("driving forward stopped: the table is in the way"), outcome.reason
        x, y, _ = robot.world.objects()["table"]
        assert math.hypot(x - table.x, y - table.y) <= 0.02, "the table was pushed"
        gap = near_face - (robot.state().pose.x + BASE_SIZE[0] / 2)
        assert 0.0 <= gap <= 0.1, gap
        assert robot.world.base_velocity() == pytest.approx((0.0, 0.0), abs=0.01)
        assert robot.backward(1.0).ok  # the bumper only holds back motion into the obstacle


def test_the_bumper_catches_a_sleeping_object_too(profile: Profile) -> None:
    with SimRobot(profile) as robot:
        robot.world.step(300)  # long enough for the objects to fall asleep
        assert robot.turnleft(math.atan2(1.8, 1.5)).ok
        outcome = robot.forward(2.8)
        assert not outcome.ok and "the ball is in the way" in outcome.reason, outcome.reason
        bx, by, _ = robot.world.objects()["ball"]
        assert math.hypot(bx - 1.5, by - 1.8) < 0.02  # not shoved, and not driven through


def test_real_time_pacing_holds_after_the_world_sat_idle(profile: Profile) -> None:
    # Issue 13: pacing against a clock fixed at start let every second of idle run unpaced later.
    with SimRobot(profile, realtime_factor=1.0) as robot:
        time.sleep(1.5)  # idle, as a daemon between tasks
        started = time.monotonic()
        sim_started = robot.world.sim_time
        assert robot.forward(1.0).ok
        wall = time.monotonic() - started
        simulated = robot.world.sim_time - sim_started
    assert simulated > 2.0
    assert wall >= simulated - 0.1, (wall, simulated)
