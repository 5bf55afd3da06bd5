"""The ROS 2 parts that need no ROS: formats, configuration, speed profiles, the goal follower."""

from __future__ import annotations

import math

import pytest

from agent.robot import Pose
from agent.ros2.config import RosConfig
from agent.ros2.geometry import footprint_radius, quaternion_from_yaw, wrap_angle, yaw_from_quaternion
from agent.ros2.goal_follower import Goal, GoalFollower
from agent.ros2.messages import (
    BumperStop,
    Footprint,
    FormatError,
    decode_bumper,
    decode_held,
    decode_objects,
    encode_bumper,
    encode_held,
    encode_objects,
)
from agent.ros2.motion import Limits, next_speed
from rsl.profile import Profile, ProfileError


def test_object_report_round_trips_with_footprints() -> None:
    text = encode_objects({"cup": (1.0, 2.0, 0.8), "table": (3.0, 0.0)}, held="cup",
                          footprints={"table": Footprint("box", (0.8, 1.2), 0.3)})
    report = decode_objects(text, "test")
    assert report.objects == {"cup": (1.0, 2.0), "table": (3.0, 0.0)}
    assert report.held == "cup"
    assert report.footprints == {"table": Footprint("box", (0.8, 1.2), 0.3)}
    assert decode_held(encode_held("cup"), "test") == "cup"


@pytest.mark.parametrize(("text", "complaint"), [
    ("{not json", "not the documented JSON"),
    ("[1, 2]", "expected a JSON object"),
    ('{"objects": [1]}', "`objects` must be a JSON object"),
    ('{"objects": {"cup": {"x": 1}}}', "object `cup` needs numeric `x` and `y`"),
    ('{"objects": {"cup": {"x": "NaN", "y": 0}}}', "not finite"),
    ('{"objects": {}, "held": 3}', "`held` must be an object name or null"),
    ('{"objects": {"t": {"x": 0, "y": 0, "footprint": {"shape": "blob", "size": [1, 1]}}}}',
     "footprint shape must be box, cylinder or sphere"),
])
def test_malformed_object_reports_say_what_is_wrong(text: str, complaint: str) -> None:
    with pytest.raises(FormatError, match="objects topic /objects") as error:
        decode_objects(text, "objects topic /objects")
    assert complaint in str(error.value)


def test_a_grasp_reply_without_held_is_rejected() -> None:
    with pytest.raises(FormatError, match="expected"):
        decode_held('{"ok": true}', "grasp reply")


def test_bumper_stops_round_trip_and_may_leave_out_what_the_robot_cannot_tell() -> None:
    stop = BumperStop("table", (2.6, -0.2), "map")
    assert decode_bumper(encode_bumper(stop), "test") == stop
    assert decode_bumper("{}", "test") == BumperStop()
    assert decode_bumper('{"obstacle": "", "x": 1, "y": 2}', "test") == BumperStop(None, (1.0, 2.0))


@pytest.mark.parametrize(("text", "complaint"), [
    ("bump!", "not the documented JSON"),
    ('{"obstacle": 3}', "`obstacle` must be an object name or null, got 3"),
    ('{"obstacle": "table", "x": 2.6}', "`x` and `y` must both be numbers or both be left out"),
    ('{"x": "near", "y": 0}', "`x` and `y` must both be numbers"),
    ('{"x": "inf", "y": 0}', "not finite"),
])
def test_malformed_bumper_stops_say_what_is_wrong(text: str, complaint: str) -> None:
    with pytest.raises(FormatError, match="bumper topic /bumper") as error:
        decode_bumper(text, "bumper topic /bumper")
    assert complaint in str(error.value)


def test_ros_config_reads_the_profile_and_rejects_bad_values(profile: Profile) -> None:
    config = RosConfig.from_profile(profile)
    assert config.cmd_vel == profile.ros["cmd_vel"]
    assert config.odom_timeout == pytest.approx(profile.ros["odom_timeout"])
    with pytest.raises(ProfileError, match=r"(?s)my\.toml: unknown setting ros\.cmd_vell\n  = help: the settings "
                                           r"here are ros\.cmd_vel, .*; see docs/ros2\.md"):
        RosConfig.from_mapping({"cmd_vell": "/x"}, source="my.toml")
    with pytest.raises(ProfileError, match=r"my\.toml: ros\.odom_timeout = 0 is not above 0\.0"):
        RosConfig.from_mapping({"odom_timeout": 0}, source="my.toml")
    with pytest.raises(ProfileError, match=r"ros\.odom must not be empty"):
        RosConfig.from_mapping({"odom": ""})
    with pytest.raises(ProfileError, match=r"ros\.goal_tolerance must be a number, not '3 cm'"):
        RosConfig.from_mapping({"goal_tolerance": "3 cm"})


def test_speed_profile_ramps_up_cruises_and_stops_on_target() -> None:
    limits = Limits(max_speed=0.5, max_accel=1.0, gain=3.0, creep=0.02)
    dt, position, speed, peak = 0.02, 0.0, 0.0, 0.0
    for _ in range(1000):
        new = next_speed(2.0 - position, speed, limits, dt)
        assert abs(new - speed) <= limits.max_accel * dt + 1e-12
        speed = new
        peak = max(peak, speed)
        position += speed * dt
        if abs(2.0 - position) <= 0.002:
            break
    assert abs(2.0 - position) <= 0.002
    assert peak == pytest.approx(0.5)
    assert next_speed(-0.3, 0.0, limits, dt) < 0  # overshoot drives back


def test_goal_follower_drives_a_kinematic_robot_onto_the_goal(profile: Profile) -> None:
    follower = GoalFollower(profile.motion)
    follower.set(Goal(-1.0, 2.0, math.pi / 2))
    x = y = heading = 0.0
    dt = 0.02
    for _ in range(5000):
        linear, angular = follower.command(Pose(x, y, heading), dt)
        assert abs(linear) <= profile.motion.max_linear_speed + 1e-9
        assert abs(angular) <= profile.motion.max_angular_speed + 1e-9
        x += linear * math.cos(heading) * dt
        y += linear * math.sin(heading) * dt
        heading = wrap_angle(heading + angular * dt)
        if follower.goal is None:
            break
    assert follower.goal is None
    assert math.hypot(x + 1.0, y - 2.0) < 0.02
    assert abs(wrap_angle(heading - math.pi / 2)) < math.radians(1.0)


def test_a_goal_at_the_robots_own_pose_stops_it_at_once(profile: Profile) -> None:
    follower = GoalFollower(profile.motion)
    follower.set(Goal(5.0, 0.0, 0.0))
    for _ in range(200):
        linear, _ = follower.command(Pose(0.0, 0.0, 0.0), 0.02)
    assert linear == pytest.approx(profile.motion.max_linear_speed)
    # Stopping a moving robot: the goal is where it was a moment ago, just behind it.
    follower.set(Goal(-0.03, 0.0, 0.0))
    linear, _ = follower.command(Pose(0.0, 0.0, 0.0), 0.02)
    assert -0.021 <= linear <= 0.0
    # The cancel idiom: a goal where the robot was a moment ago, heading slightly off,
    # stops it where it is instead of turning it back.
    follower.set(Goal(-0.01, 0.0, math.radians(3.0)))
    assert follower.command(Pose(0.0, 0.0, 0.0), 0.02) == (0.0, 0.0)
    assert follower.goal is None


def test_geometry_helpers() -> None:
    for yaw in (-3.0, -1.0, 0.0, 0.5, 3.1):
        assert yaw_from_quaternion(*quaternion_from_yaw(yaw)) == pytest.approx(yaw)
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert footprint_radius("box", (0.8, 1.2), 0.0, 0.0) == pytest.approx(0.4)
    assert footprint_radius("box", (0.8, 1.2), 0.0, math.pi / 2) == pytest.approx(0.6)
    assert footprint_radius("cylinder", (0.1, 0.1), 0.0, 1.0) == pytest.approx(0.05)
