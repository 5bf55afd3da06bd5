"""The shared robot programs (tests/sim/scenarios.py, the same the pybullet backend
runs), through the ROS 2 backend against `nrtrans sim-bridge` over real DDS: the
backend here, the simulated robot in another process."""

from __future__ import annotations

import pytest

from agent.executor import execute
from agent.robot import CancelToken, Outcome, RobotState
from agent.ros2.backend import Ros2Robot
from rsl.compiler import compile_program
from rsl.profile import Profile
from tests.sim.scenarios import SCENARIOS, Scenario, check_final_state, check_moves_and_turns

REALTIME_FACTOR = 2.0


def run_program(robot: Ros2Robot, profile: Profile, program: str) -> tuple[RobotState, tuple[Outcome, ...]]:
    """Compile and run through the real executor, watchdog included, as the daemon does."""
    result = compile_program(program, profile)
    assert result.ok, [d.brief() for d in result.diagnostics]
    assert result.plan is not None
    run = execute(result.plan, robot, profile, cancel=CancelToken())
    failed = [(c.to_rsl(), o.reason) for c, o in zip(result.plan, run.outcomes, strict=False) if not o.ok]
    assert run.ok, failed
    assert run.final_state is not None
    return run.final_state, run.outcomes


@pytest.mark.parametrize("scenario", SCENARIOS, ids=lambda s: s.name)
def test_scenario_ends_where_expected(scenario: Scenario, robot: Ros2Robot, profile: Profile) -> None:
    state, outcomes = run_program(robot, profile, scenario.program)
    assert check_final_state(scenario, state, outcomes) == []


def test_each_straight_move_and_turn_is_within_2cm_and_1_degree(robot: Ros2Robot) -> None:
    check_moves_and_turns(robot)


def test_the_head_stops_at_its_joint_limits(robot: Ros2Robot, profile: Profile) -> None:
    outcome = robot.lookleft(3.0)
    assert outcome.ok and f"pan limited to {profile.head['pan'][1]:g} rad" in outcome.reason
    assert robot.state().head_pan == pytest.approx(profile.head["pan"][1], abs=0.01)
    outcome = robot.lookdown(1.2)
    assert outcome.ok and "tilt limited to -0.6 rad" in outcome.reason
    assert robot.state().head_tilt == pytest.approx(profile.head["tilt"][0], abs=0.01)


def test_grasp_refuses_when_another_object_is_nearer_the_gripper(robot: Ros2Robot) -> None:
    assert robot.perceive().ok
    assert robot.approach("bottle").ok
    outcome = robot.grasp("cup")
    assert not outcome.ok
    assert "bottle is nearer to the gripper than cup" in outcome.reason
    assert robot.state().holding is None
    assert robot.grasp("bottle").ok
    assert robot.state().holding == "bottle"
