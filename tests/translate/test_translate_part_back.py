"""A task that ends by putting a part back as it was ("..., then look straight ahead again")."""

from __future__ import annotations

import pytest

from agent.normalize import normalize_task
from agent.translate import Translator
from agent.translate.part_back import put_back, undoing
from rsl.compiler import compile_program
from rsl.profile import Profile


@pytest.mark.parametrize(("task", "before"), [
    ("Look left 30 degrees, then look straight ahead again.", "look left 0.5236 rad"),
    ("Look down 20 degrees and then bring your head back level.", "look down 0.3491 rad"),
    ("look up and left, then center your head please", "look up and left"),
    # The phrase said first opens the task; the one said last ends it.
    ("Look straight ahead, then look left 30 degrees, then look straight ahead.",
     "look straight ahead, then look left 0.5236 rad"),
])
def test_the_clause_that_puts_the_head_back_is_cut_from_what_the_model_reads(
        profile: Profile, task: str, before: str) -> None:
    found = put_back(normalize_task(task), profile)
    assert found is not None and found.part == "head" and found.before == before


@pytest.mark.parametrize("task", [
    "look straight ahead",  # nothing before it to undo
    "keep looking straight ahead and drive forward 2 metres",  # not the last clause
    "look straight ahead again and then turn left",
    "look left 30 degrees",
])
def test_a_task_that_does_not_end_by_putting_a_part_back_is_read_whole(profile: Profile, task: str) -> None:
    assert put_back(normalize_task(task), profile) is None


def _undoing(program: str, profile: Profile) -> str:
    result = compile_program(program, profile)
    assert result.ok and result.plan is not None
    return undoing(result.plan, "head", profile)


def test_the_head_is_put_back_by_its_net_movement_the_last_moved_first(profile: Profile) -> None:
    assert _undoing("lookup 0.3; lookleft 0.5; forward 1; lookright 0.2; lookleft 0.1;", profile) == (
        "lookright 0.4;\nlookdown 0.3;\n")


def test_a_head_that_ends_where_it_began_or_never_moved_needs_no_step(profile: Profile) -> None:
    assert _undoing("lookleft 1.5708; perceive; lookright 3.1416; perceive; lookleft 1.5708;", profile) == ""
    assert _undoing("forward 2; turnleft 1.5708;", profile) == ""


@pytest.mark.parametrize(("task", "program"), [
    # Read whole, the model tilted down twice: "back level" is not an amount it knows how to undo.
    ("Look down 20 degrees and then bring your head back level.", "lookdown 0.3491;\nlookup 0.3491;\n"),
    # Read whole, "straight ahead" drove the base.
    ("Look left 30 degrees, then look straight ahead again.", "lookleft 0.5236;\nlookright 0.5236;\n"),
])
def test_the_translator_puts_the_head_back_by_what_it_moved(adapted: Translator, task: str, program: str) -> None:
    result = adapted.translate(task)
    assert result.verified and result.program == program
    assert result.explanation.startswith("look ")
