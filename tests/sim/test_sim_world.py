"""Scene files and the physics world underneath the skills."""

from __future__ import annotations

import math
import time

import pytest

from agent.backends import BackendError, open_robot
from agent.robot import Robot
from agent.sim.robot import SimRobot
from agent.sim.scene import SceneError, load_scene, parse_scene
from agent.sim.world import SimWorld
from rsl.profile import Profile


def test_default_scene_has_the_named_objects() -> None:
    scene = load_scene()
    for name in ("table", "cup", "bottle", "door", "ball", "book", "banana", "tool", "workbench", "chair"):
        assert scene.object(name) is not None, name
    assert scene.object("cup").graspable and not scene.object("table").graspable


@pytest.mark.parametrize(("text", "message"), [
    ("[[objects]]\nname = 'Big Cup'\nx = 1\ny = 1\n", "must be an identifier"),
    ("[[objects]]\nname = 'cup'\nx = 1\n", "every object needs x and y"),
    ("[[objects]]\nname = 'cup'\nx = 1\ny = 0\nshape = 'cone'\n", "shape 'cone' must be one of box"),
    ("[[objects]]\nname = 'cup'\nx = 1\ny = 0\nsize = [0, 1, 1]\n", "size and mass must be positive"),
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


def test_resting_objects_wake_when_the_robot_pushes_them(profile: Profile) -> None:
    robot = SimRobot(profile)
    try:
        robot.world.step(300)  # long enough for the objects to fall asleep
        assert robot.turnleft(math.atan2(1.8, 1.5)).ok
        assert robot.forward(2.8).ok
        bx, by, _ = robot.world.objects()["ball"]
        assert math.hypot(bx - 1.5, by - 1.8) > 0.5  # shoved ahead of the base, not driven through
    finally:
        robot.close()
