"""Steps that must not finish: unknown objects, out of reach, cancel and stop mid-motion, timeouts."""

from __future__ import annotations

import dataclasses
import math
import threading
import time

import pytest

from agent.executor import execute, step_timeout
from agent.robot import CancelToken, Outcome, Status
from agent.sim.robot import SimRobot
from agent.sim.scene import parse_scene
from rsl.compiler import compile_program
from rsl.profile import Profile, default_profile_path, parse_profile

WALL_SCENE = """
[[objects]]
name = "wall"
kind = "fixed"
x = 1.2
y = 0.0
size = [0.1, 3.0, 1.0]
"""


def plan_of(program: str, profile: Profile):
    result = compile_program(program, profile)
    assert result.ok, [d.brief() for d in result.diagnostics]
    return result.plan


def test_an_object_not_in_the_scene_fails_with_the_names_there(robot: SimRobot) -> None:
    outcome = robot.approach("unicorn")
    assert outcome.status is Status.FAILED
    assert "no unicorn in the scene" in outcome.reason and "cup" in outcome.reason
    assert robot.state().pose.x == pytest.approx(0.0, abs=1e-6)


def test_an_object_out_of_view_is_refused_and_one_in_view_is_looked_for(robot: SimRobot) -> None:
    outcome = robot.grasp("book")  # behind the robot
    assert outcome.status is Status.FAILED
    assert "cannot see it from here" in outcome.reason and "look around first" in outcome.reason
    assert "known objects: bottle, cup, table" in outcome.reason
    assert robot.state().pose.x == pytest.approx(0.0, abs=1e-6)
    assert robot.approach("table").ok  # in view, though never perceived by name


def test_grasp_out_of_reach_says_how_far(robot: SimRobot) -> None:
    assert robot.perceive().ok
    outcome = robot.grasp("cup")
    assert outcome.status is Status.FAILED
    assert outcome.reason.startswith("cup is 2.69 m away, out of reach 0.8 m")
    assert robot.state().holding is None
    assert robot.world.objects()["cup"][:2] == pytest.approx((2.68, 0.25), abs=0.01)  # it did not move


def test_grasp_refuses_furniture_and_a_second_object(robot: SimRobot) -> None:
    assert robot.perceive().ok and robot.approach("table").ok
    outcome = robot.grasp("table")
    assert not outcome.ok and "cannot be picked up" in outcome.reason
    assert robot.grasp("cup").ok
    outcome = robot.grasp("bottle")
    assert not outcome.ok and "already holding cup" in outcome.reason


def test_grasp_refuses_when_another_object_is_nearer(robot: SimRobot) -> None:
    assert robot.perceive().ok and robot.approach("bottle").ok
    outcome = robot.grasp("cup")
    assert not outcome.ok and "bottle is nearer to the gripper than cup" in outcome.reason
    assert robot.grasp("bottle").ok and robot.state().holding == "bottle"


def _cancel_when_moving(robot: SimRobot, act) -> float:
    """Set the cancel once the base cruises; returns the wall time of the cancel."""
    cancelled_at = 0.0
    while robot.state().pose.x < 0.6:
        time.sleep(0.005)
    cancelled_at = time.monotonic()
    act()
    return cancelled_at


def _stopped_within(robot: SimRobot, since_wall: float) -> tuple[float, float]:
    """Sim and wall seconds from `since_wall` until the base stood still."""
    samples = [s for s in robot.world.trajectory if s.wall_time >= since_wall]
    first = samples[0]
    assert abs(first.linear) > 0.3, "the base was not moving when the cancel came"
    still = next(s for s in samples if abs(s.linear) < 0.005 and abs(s.angular) < 0.01)
    return still.sim_time - first.sim_time, still.wall_time - since_wall


def test_cancel_mid_motion_stops_the_base_within_0_2_s(profile: Profile) -> None:
    with SimRobot(profile, realtime_factor=1.0) as robot:
        token = CancelToken()
        result: list[Outcome] = []
        worker = threading.Thread(target=lambda: result.append(robot.forward(5.0, cancel=token)))
        worker.start()
        at = _cancel_when_moving(robot, lambda: token.set("operator cancel"))
        worker.join(timeout=5)
        sim_s, wall_s = _stopped_within(robot, at)
        assert result == [Outcome.cancelled("operator cancel")]
        assert sim_s <= 0.2 and wall_s <= 0.2, (sim_s, wall_s)
        stopped = robot.state().pose.x
        assert 0.6 < stopped < 0.8  # it did not go on to 5 m


def test_executor_cancel_mid_motion_stops_and_runs_no_further_step(profile: Profile) -> None:
    with SimRobot(profile, realtime_factor=1.0) as robot:
        token = CancelToken()
        results = []
        plan = plan_of("forward 5; turnleft 1;", profile)
        worker = threading.Thread(target=lambda: results.append(execute(plan, robot, profile, cancel=token)))
        worker.start()
        at = _cancel_when_moving(robot, lambda: token.set("emergency stop"))
        worker.join(timeout=5)
        sim_s, wall_s = _stopped_within(robot, at)
        assert sim_s <= 0.2 and wall_s <= 0.2, (sim_s, wall_s)
        (result,) = results
        assert result.status is Status.CANCELLED
        assert result.outcomes == (Outcome.cancelled("emergency stop"),)
        assert result.final_state.pose.heading == pytest.approx(0.0, abs=1e-3)


def test_stop_from_another_thread_ends_the_motion(profile: Profile) -> None:
    with SimRobot(profile, realtime_factor=1.0) as robot:
        result: list[Outcome] = []
        worker = threading.Thread(target=lambda: result.append(robot.forward(5.0)))
        worker.start()
        at = _cancel_when_moving(robot, robot.stop)
        worker.join(timeout=5)
        sim_s, _wall_s = _stopped_within(robot, at)
        assert result[0].status is Status.CANCELLED and sim_s <= 0.2
        assert robot.forward(0.2).ok  # a later step runs normally


def test_a_blocked_motion_stops_at_the_obstacle_with_what_is_left(profile: Profile) -> None:
    with SimRobot(profile, parse_scene(WALL_SCENE, "wall")) as robot:
        result = execute(plan_of("forward 3; turnleft 1;", profile), robot, profile)
        assert result.status is Status.FAILED and len(result.outcomes) == 1
        reason = result.outcomes[0].reason
        assert "the wall is in the way" in reason and "2.11 m still to go" in reason, reason
        assert robot.state().pose.x < 1.0  # the wall held it
        assert robot.world.base_velocity() == pytest.approx((0.0, 0.0), abs=0.01)


def test_the_executor_watchdog_stops_a_step_slower_than_its_budget(profile: Profile) -> None:
    # The executor believes a far faster robot than the simulator's, so only its
    # wall-clock watchdog can end the step.
    claimed = dataclasses.replace(profile, motion=dataclasses.replace(
        profile.motion, max_linear_speed=5.0, max_linear_accel=10.0, timeout_margin=0.5))
    plan = plan_of("forward 3;", claimed)
    budget = step_timeout(plan.commands[0], claimed)
    with SimRobot(profile, realtime_factor=1.0) as robot:
        started = time.monotonic()
        result = execute(plan, robot, claimed)
        took = time.monotonic() - started
    assert result.status is Status.FAILED
    assert result.outcomes[0].reason.startswith(f"`forward 3;` timed out after {budget:.1f} s")
    assert budget + 1.5 < took < budget + 4.0  # the 2 s grace, then braking


def test_a_skill_without_a_binding_fails_clearly(robot: SimRobot) -> None:
    wave = '\n[[skills]]\nkeyword = "wave"\ndescription = "Wave."\nexample = "wave;"\nparams = []\n'
    extra = default_profile_path().read_text(encoding="utf-8") + wave
    waving = parse_profile(extra)
    result = execute(plan_of("forward 0.1; wave; forward 0.1;", waving), robot, waving)
    assert result.status is Status.FAILED
    assert [o.status for o in result.outcomes] == [Status.DONE, Status.FAILED]
    assert "the skill `wave` declares no binding" in result.outcomes[1].reason


def test_the_simulator_itself_refuses_a_skill_without_a_binding(robot: SimRobot) -> None:
    wave = '\n[[skills]]\nkeyword = "wave"\ndescription = "Wave."\nexample = "wave;"\nparams = []\n'
    waving = parse_profile(default_profile_path().read_text(encoding="utf-8") + wave)
    skill = waving.skill("wave")
    assert skill is not None
    outcome = robot.perform(skill, ())
    assert outcome == Outcome.failed("the sim backend cannot run `wave`: it declares no binding in profile default")


def test_a_skill_bound_to_ros_runs_in_the_simulator_as_not_simulated(robot: SimRobot) -> None:
    dock = ('\n[[skills]]\nkeyword = "dock"\ndescription = "Dock."\nexample = "dock;"\nparams = []\n'
            'binding = { ros = "trigger", service = "/dock" }\n')
    docking = parse_profile(default_profile_path().read_text(encoding="utf-8") + dock)
    result = execute(plan_of("forward 0.1; dock; forward 0.1;", docking), robot, docking)
    assert result.ok, result
    assert result.outcomes[1].reason.startswith("not simulated: `dock` calls the std_srvs/srv/Trigger service /dock")
    assert robot.state().pose.x == pytest.approx(0.2, abs=0.005)  # the steps after it ran too


def test_a_cancel_before_the_plan_starts_runs_nothing(robot: SimRobot, profile: Profile) -> None:
    token = CancelToken()
    token.set("cancelled by the user")
    result = execute(plan_of("forward 1;", profile), robot, profile, cancel=token)
    assert result.status is Status.CANCELLED
    assert result.outcomes == (Outcome.cancelled("cancelled by the user"),)
    assert robot.state().pose.x == pytest.approx(0.0, abs=1e-6)


def test_goto_outside_the_workspace_is_refused_by_the_robot_too(robot: SimRobot) -> None:
    outcome = robot.goto(12.0, 0.0)
    assert not outcome.ok and "outside the workspace" in outcome.reason
    assert math.hypot(robot.state().pose.x, robot.state().pose.y) < 1e-6


def test_a_closed_simulator_refuses_steps(profile: Profile) -> None:
    robot = SimRobot(profile)
    robot.close()
    assert robot.forward(1.0) == Outcome.failed("the simulator is closed")
    robot.close()  # twice is harmless


def test_a_failing_event_handler_does_not_stop_the_plan(robot: SimRobot, profile: Profile, caplog) -> None:
    seen = []

    def handler(event) -> None:
        seen.append(event.index)
        raise IndexError("bug in a progress display")

    result = execute(plan_of("forward 0.2; turnleft 0.2;", profile), robot, profile, on_event=handler)
    assert result.status is Status.DONE and seen == [1, 1, 2, 2]
    assert "the step event handler failed" in caplog.text
