"""The shared robot programs and where each must leave the robot in the default scene.

Every backend runs the same programs: `tests/sim` on the pybullet robot
directly, and the ROS 2 tests through `nrtrans sim-bridge`. Import
`SCENARIOS` and `check_final_state` from here rather than copying them, so the
backends are held to one standard.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from agent.robot import Outcome, Robot, RobotState

POSITION_TOLERANCE = 0.05  # m
HEADING_TOLERANCE = math.radians(2.0)
HEAD_TOLERANCE = 0.03  # rad


@dataclass(frozen=True)
class Scenario:
    name: str
    program: str
    x: float
    y: float
    heading: float | None  # None: any heading will do
    holding: str | None = None
    seen: tuple[str, ...] = ()  # objects `perceive` must report
    head: tuple[float, float] = (0.0, 0.0)  # pan, tilt at the end


SCENARIOS = (
    Scenario("square_left", "forward 1; turnleft 1.5708; forward 1; turnleft 1.5708; "
                            "forward 1; turnleft 1.5708; forward 1; turnleft 1.5708;", 0.0, 0.0, 0.0),
    Scenario("square_right_backward", "backward 0.5; turnright 1.5708; forward 0.5; turnright 1.5708; "
                                      "forward 0.5;", -1.0, -0.5, math.pi),
    Scenario("approach_then_grasp", "perceive; approach table; grasp cup;", 2.1, 0.0, 0.0, holding="cup",
             seen=("table", "cup", "bottle")),
    Scenario("look_around", "lookdown 0.3; lookleft 1.5708; perceive; lookright 3.1416; perceive; "
                            "lookleft 1.5708; lookup 0.3;", 0.0, 0.0, 0.0, seen=("ball", "book", "banana")),
    Scenario("goto_and_back", "goto 1.5, -1; goto 0, 0;", 0.0, 0.0, None),
    Scenario("fetch_and_return", "perceive; approach bottle; grasp bottle; goto 0, 0; turnleft 3.1416;",
             0.0, 0.0, None, holding="bottle", seen=("bottle",)),
)


def seen_in(outcomes: list[Outcome] | tuple[Outcome, ...]) -> set[str]:
    """The objects that `perceive` steps reported ("saw a, b")."""
    return {name.strip() for o in outcomes if o.reason.startswith("saw ") and o.reason != "saw no objects"
            for name in o.reason.removeprefix("saw ").split(",")}


def check_final_state(scenario: Scenario, state: RobotState,
                      outcomes: list[Outcome] | tuple[Outcome, ...]) -> list[str]:
    """What is wrong with the robot's final state for `scenario`; empty when it is right."""
    problems = []
    off = math.hypot(state.pose.x - scenario.x, state.pose.y - scenario.y)
    if off > POSITION_TOLERANCE:
        problems.append(f"ended at ({state.pose.x:.3f}, {state.pose.y:.3f}), {off:.3f} m from "
                        f"({scenario.x}, {scenario.y})")
    if scenario.heading is not None:
        turn = abs(math.remainder(state.pose.heading - scenario.heading, 2 * math.pi))
        if turn > HEADING_TOLERANCE:
            problems.append(f"heading {state.pose.heading:.3f} rad is {math.degrees(turn):.1f} degrees off")
    if state.holding != scenario.holding:
        problems.append(f"holding {state.holding!r}, expected {scenario.holding!r}")
    pan, tilt = scenario.head
    if abs(state.head_pan - pan) > HEAD_TOLERANCE or abs(state.head_tilt - tilt) > HEAD_TOLERANCE:
        problems.append(f"head at pan {state.head_pan:.3f}, tilt {state.head_tilt:.3f}; expected {scenario.head}")
    missing = set(scenario.seen) - seen_in(outcomes)
    if missing:
        problems.append(f"perceive never reported {', '.join(sorted(missing))}")
    return problems


def check_moves_and_turns(robot: Robot) -> None:
    """Straight moves and turns end within 2 cm and 1 degree, on any backend."""
    start = robot.state().pose
    assert robot.forward(0.73).ok
    moved = robot.state().pose
    assert abs(math.hypot(moved.x - start.x, moved.y - start.y) - 0.73) < 0.02
    assert robot.turnright(2.5).ok
    turned = robot.state().pose
    assert abs(math.remainder(turned.heading - (moved.heading - 2.5), 2 * math.pi)) < math.radians(1.0)
    assert robot.turnleft(6.2832 + 0.5).ok  # more than a full circle counts it
    again = robot.state().pose
    assert abs(math.remainder(again.heading - (turned.heading + 0.5), 2 * math.pi)) < math.radians(1.0)
    assert robot.backward(1.2).ok
    back = robot.state().pose
    assert abs(math.hypot(back.x - again.x, back.y - again.y) - 1.2) < 0.02
    assert abs(math.remainder(back.heading - again.heading, 2 * math.pi)) < math.radians(1.0)
