"""text or RSL -> translation -> verified plan -> outcome, with the real compiler, translator and simulator."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from agent.executor import StepEvent
from agent.pipeline import Attempted, Cancelled, Draft, Finished, Pipeline, Rejected, Verified
from agent.robot import CancelToken, Status
from agent.sim.robot import SimRobot
from agent.translate import Translator
from agent.translate.model_path import resolve_model
from rsl.profile import Profile, default_profile_path, load_profile


@pytest.fixture(scope="module")
def translator(profile: Profile) -> Iterator[Translator]:
    loaded = Translator.load(profile, model=str(resolve_model(None)))
    yield loaded
    loaded.close()


@pytest.fixture
def pipeline(profile: Profile, translator: Translator) -> Iterator[Pipeline]:
    with SimRobot(profile) as robot:
        yield Pipeline(profile, translator, robot)


def test_an_rsl_program_is_compiled_checked_and_run_to_done(pipeline: Pipeline) -> None:
    attempts: list[Attempted] = []
    draft = pipeline.compile("perceive; grasp cup;", None, attempts.append)
    assert isinstance(draft, Draft) and attempts == [Attempted(1, "perceive; grasp cup;", ())]
    verified = pipeline.verify(draft)
    assert isinstance(verified, Verified)
    # The cup is out of the arm's reach: the world check puts the profile's approach before the grasp.
    assert verified.program == "perceive;\napproach cup;\ngrasp cup;\n"
    assert verified.explanation
    steps: list[StepEvent] = []
    finished = pipeline.execute(verified, cancel=CancelToken(), on_event=steps.append)
    assert isinstance(finished, Finished) and finished.status is Status.DONE and finished.reason == ""
    assert finished.robot_state is not None and finished.robot_state["holding"] == "cup"
    assert [s.index for s in steps if s.outcome is not None] == [1, 2, 3]
    assert pipeline.known_objects() is not None and "cup" in pipeline.known_objects()


def test_a_program_that_does_not_compile_is_rejected_with_its_diagnostics(pipeline: Pipeline) -> None:
    attempts: list[Attempted] = []
    rejected = pipeline.compile("forward -1;", None, attempts.append)
    assert isinstance(rejected, Rejected) and "does not compile" in rejected.reason
    assert rejected.diagnostics and rejected.diagnostics == attempts[0].diagnostics
    assert rejected.diagnostics[0]["code"] == "E102"  # a negative amount


def test_a_drive_into_a_seen_obstacle_is_rejected_before_it_runs(pipeline: Pipeline) -> None:
    looked = pipeline.compile("perceive;", None)
    assert isinstance(looked, Draft)
    verified = pipeline.verify(looked)
    assert isinstance(verified, Verified)
    assert pipeline.execute(verified, cancel=CancelToken()).status is Status.DONE
    draft = pipeline.compile("forward 4;", pipeline.known_objects())
    assert isinstance(draft, Draft)
    refused = pipeline.verify(draft)
    assert isinstance(refused, Rejected) and "would drive into the table" in refused.reason


def test_a_cancelled_run_ends_cancelled_with_the_reason(pipeline: Pipeline) -> None:
    draft = pipeline.compile("forward 1;", None)
    assert isinstance(draft, Draft)
    verified = pipeline.verify(draft)
    assert isinstance(verified, Verified)
    cancel = CancelToken()
    cancel.set("stopped by the test")
    finished = pipeline.execute(verified, cancel=cancel)
    assert finished.status is Status.CANCELLED and finished.reason == "stopped by the test"


def test_a_spoken_task_is_translated_verified_and_run(pipeline: Pipeline) -> None:
    attempts: list[Attempted] = []
    draft = pipeline.translate("move forward half a meter", None, cancel=CancelToken(), on_attempt=attempts.append)
    assert isinstance(draft, Draft), draft
    assert [a.number for a in attempts] == list(range(1, len(attempts) + 1)) and not attempts[-1].diagnostics
    assert draft.model and draft.timings_ms["total"] > 0 and draft.confidence is not None
    verified = pipeline.verify(draft)
    assert isinstance(verified, Verified) and verified.program == "forward 0.5;\n"
    finished = pipeline.execute(verified, cancel=CancelToken())
    assert finished.status is Status.DONE and finished.robot_state is not None
    assert finished.robot_state["pose"]["x"] == pytest.approx(0.5, abs=0.05)


def test_a_translation_cancelled_before_it_starts_makes_no_plan(pipeline: Pipeline) -> None:
    cancel = CancelToken()
    cancel.set("cancelled by request")
    assert pipeline.translate("turn left", None, cancel=cancel) == Cancelled("cancelled by request")


def test_a_request_the_robot_cannot_carry_out_is_rejected_with_what_it_can_do() -> None:
    turtlebot = load_profile(default_profile_path().with_name("turtlebot.toml"))
    translator = Translator.load(turtlebot, model=str(resolve_model(None)))
    try:
        with SimRobot(turtlebot) as robot:
            rejected = Pipeline(turtlebot, translator, robot).translate("pick up the cup", None, cancel=CancelToken())
    finally:
        translator.close()
    assert isinstance(rejected, Rejected), rejected
    assert rejected.reason.startswith("not understood as a task for this robot; nothing moved. It can: ")
    assert rejected.diagnostics[0]["code"] == "E201" and len(rejected.attempts) == 1
