"""The second shipped profile: a base-only robot. Its requests for an arm are refused with the
reason; what it can do translates (base model with shots) and runs on the simulator."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from agent.executor import execute
from agent.sim.robot import SimRobot
from agent.translate import Translator
from agent.translate.model_path import resolve_model
from rsl.compiler import compile_program
from rsl.profile import Profile, load_profile

TURTLEBOT = Path(__file__).resolve().parents[2] / "rsl" / "profiles" / "turtlebot.toml"


@pytest.fixture(scope="module")
def turtlebot() -> Profile:
    return load_profile(TURTLEBOT)


@pytest.fixture(scope="module")
def translator(turtlebot: Profile) -> Iterator[Translator]:
    loaded = Translator.load(turtlebot, model=str(resolve_model(None)))
    yield loaded
    loaded.close()


def test_it_has_a_base_a_camera_and_a_dock_but_no_head_or_arm(turtlebot: Profile) -> None:
    primitives = {s.primitive.name for s in turtlebot.skills if s.primitive is not None}
    assert primitives == {"drive", "turn", "navigate", "perceive_objects", "approach_object"}
    assert turtlebot.ros["cmd_vel"] == "/tb4/cmd_vel"
    assert turtlebot.skill("dock") is not None and turtlebot.bound_to("grasp_object") is None


def test_pick_up_the_cup_is_refused_with_the_reason(translator: Translator) -> None:
    result = translator.translate("pick up the cup", known_objects=["cup"])
    assert not result.verified and result.plan is None and result.passes == 0
    [diagnostic] = result.attempts[-1].diagnostics
    assert diagnostic.code.code == "E201"
    assert diagnostic.message.startswith(
        "'pick up the cup' asks the turtlebot robot to pick up, and it cannot pick things up, hold or carry "
        "them: it has no arm or gripper. Nothing was run. It can: `forward`, `backward`")


def test_what_it_can_do_translates_through_the_base_model(translator: Translator) -> None:
    assert "+" not in translator.model_name  # no adapter: the shipped one is for the default robot
    result = translator.translate("move forward 2 meters")
    assert result.verified and result.program.strip() == "forward 2;"


def test_a_hand_written_grasp_is_an_unknown_command(turtlebot: Profile) -> None:
    [diagnostic] = compile_program("grasp cup;", turtlebot, ["cup"]).diagnostics
    assert diagnostic.code.code == "E006"


def test_it_runs_on_the_simulator_with_its_dock_not_simulated(turtlebot: Profile) -> None:
    plan = compile_program("undock; forward 1; turnleft 1.5708; goto 0, 0; dock;", turtlebot).plan
    assert plan is not None
    with SimRobot(turtlebot) as robot:
        result = execute(plan, robot, turtlebot)
    assert result.ok, [o.reason for o in result.outcomes]
    assert result.outcomes[0].reason.startswith("not simulated: `undock` calls the std_srvs/srv/Trigger "
                                                 "service /tb4/undock")
    assert result.final_state is not None and abs(result.final_state.pose.x) < 0.01
