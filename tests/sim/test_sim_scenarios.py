"""The shared programs (tests/sim/scenarios.py) through the executor on the pybullet robot."""

from __future__ import annotations

import itertools
import math

import pytest

from agent.executor import StepEvent, execute
from agent.robot import Status
from agent.sim.robot import SimRobot
from rsl.compiler import compile_program
from rsl.profile import Profile
from tests.sim.scenarios import SCENARIOS, Scenario, check_final_state, check_moves_and_turns


def plan_of(program: str, profile: Profile):
    result = compile_program(program, profile)
    assert result.ok, [d.brief() for d in result.diagnostics]
    return result.plan


@pytest.mark.parametrize("scenario", SCENARIOS, ids=lambda s: s.name)
def test_scenario_ends_where_expected(scenario: Scenario, robot: SimRobot, profile: Profile) -> None:
    events: list[StepEvent] = []
    plan = plan_of(scenario.program, profile)
    result = execute(plan, robot, profile, on_event=events.append)
    assert result.status is Status.DONE, [o.reason for o in result.outcomes]
    assert result.final_state is not None
    assert check_final_state(scenario, result.final_state, result.outcomes) == []
    # Two events per step: started (no outcome), then finished, in order.
    assert [(e.index, e.outcome is None) for e in events] == [
        (i, started) for i in range(1, len(plan) + 1) for started in (True, False)]
    assert all(e.total == len(plan) for e in events)
    assert [e.statement for e in events[::2]] == [c.to_rsl() for c in plan.commands]


def test_straight_moves_and_turns_within_2cm_and_1_degree(robot: SimRobot) -> None:
    check_moves_and_turns(robot)


def test_motions_respect_the_profile_speed_and_acceleration(robot: SimRobot, profile: Profile) -> None:
    world = robot.world
    first = len(world.trajectory)
    assert robot.forward(2).ok
    assert robot.turnleft(3).ok
    samples = list(world.trajectory)[first:]
    motion = profile.motion
    assert max(abs(s.linear) for s in samples) <= motion.max_linear_speed + 1e-6
    assert max(abs(s.angular) for s in samples) <= motion.max_angular_speed + 1e-6
    assert max(abs(s.linear) for s in samples) > 0.9 * motion.max_linear_speed  # it did reach cruise speed
    accels = [abs(b.linear - a.linear) / world.dt for a, b in itertools.pairwise(samples)]
    assert max(accels) <= motion.max_linear_accel * 1.05


def test_head_is_clamped_to_its_limits_and_says_so(robot: SimRobot, profile: Profile) -> None:
    outcome = robot.lookleft(3.0)
    assert outcome.ok and f"pan limited to {profile.head['pan'][1]:g} rad" in outcome.reason
    assert robot.state().head_pan == pytest.approx(profile.head["pan"][1], abs=0.01)
    outcome = robot.lookdown(1.2)
    assert outcome.ok and "tilt limited to -0.6 rad" in outcome.reason
    assert robot.state().head_tilt == pytest.approx(profile.head["tilt"][0], abs=0.01)
    outcome = robot.lookright(0.5)
    assert outcome.ok and outcome.reason == ""
    assert robot.state().head_pan == pytest.approx(profile.head["pan"][1] - 0.5, abs=0.01)
    assert robot.state().pose.heading == pytest.approx(0.0, abs=1e-3)  # the base did not turn


def test_perceive_reports_only_what_the_camera_sees(robot: SimRobot) -> None:
    assert robot.perceive().reason == "saw bottle, cup, table"
    assert {name for name, _x, _y in robot.state().known_objects} == {"bottle", "cup", "table"}
    assert robot.turnleft(3.1416).ok
    outcome = robot.perceive()
    assert outcome.ok and "door" in outcome.reason and "cup" not in outcome.reason
    known = {name: (x, y) for name, x, y in robot.state().known_objects}
    assert known["door"] == pytest.approx((-4.0, 0.0), abs=0.01)


def test_approach_stops_at_standoff_facing_the_object(robot: SimRobot, profile: Profile) -> None:
    assert robot.turnleft(1.0).ok
    assert robot.perceive().ok
    assert robot.approach("ball").ok
    pose = robot.state().pose
    bx, by, _ = robot.world.objects()["ball"]
    radius = 0.1
    assert math.hypot(bx - pose.x, by - pose.y) == pytest.approx(profile.motion.standoff + radius, abs=0.02)
    facing = math.atan2(by - pose.y, bx - pose.x)
    assert abs(math.remainder(pose.heading - facing, 2 * math.pi)) < math.radians(1.0)


def test_grasped_object_travels_with_the_robot(robot: SimRobot) -> None:
    assert robot.perceive().ok and robot.approach("table").ok and robot.grasp("cup").ok
    assert robot.goto(-1.0, 1.0).ok
    cx, cy, cz = robot.world.objects()["cup"]
    pose = robot.state().pose
    assert math.hypot(cx - pose.x, cy - pose.y) < 0.5
    assert cz > 0.7  # still up in the gripper, not dropped on the floor


def test_approach_from_too_close_backs_up_and_twice_is_a_no_op(robot: SimRobot) -> None:
    assert robot.perceive().ok and robot.approach("table").ok
    there = robot.state().pose
    assert robot.approach("table").ok
    again = robot.state().pose
    assert math.hypot(again.x - there.x, again.y - there.y) < 0.005
    assert robot.forward(0.2).ok
    assert robot.approach("table").ok
    back = robot.state().pose
    assert math.hypot(back.x - there.x, back.y - there.y) < 0.01
    assert abs(math.remainder(back.heading - there.heading, 2 * math.pi)) < math.radians(1.0)
    # It backed straight up rather than turning round in front of the table.
    assert min(abs(math.remainder(s.heading, 2 * math.pi)) for s in list(robot.world.trajectory)[-200:]) < 0.05
    assert max(abs(math.remainder(s.heading, 2 * math.pi)) for s in list(robot.world.trajectory)[-200:]) < 0.05
