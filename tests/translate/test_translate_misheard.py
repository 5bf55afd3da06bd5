"""A recognizer's "write" for "right", read back where the verb cannot be meant, and only at run time."""

from __future__ import annotations

import random

import pytest

from agent.adapter.data import asr_noise
from agent.normalize import normalize_task
from agent.translate import Translator
from agent.translate.misheard import heard
from rsl.profile import load_profile

PROFILE = load_profile()


@pytest.mark.parametrize(("said", "read"), [
    ("turn write", "turn right"),
    ("turn rite ninety degrees", "turn right 1.5708 rad"),
    ("turn around to the write", "turn around to the right"),
    ("hang a write, then go two metres", "hang a right, then go 2 m"),
    ("make a write turn", "make a right turn"),
    ("turn write a little", "turn right a little"),
    ("write forty five degrees", "right 0.7854 rad"),
])
def test_write_where_the_verb_cannot_be_meant_is_right(said: str, read: str) -> None:
    assert heard(said, PROFILE) == read


@pytest.mark.parametrize("said", [
    "write a note",
    "can you write",
    "could you write it down",
    "i will write 5 lines",
    "please write, then turn left",
])
def test_write_that_may_be_the_verb_is_left_alone(said: str) -> None:
    assert heard(said, PROFILE) == normalize_task(said)


@pytest.mark.parametrize(("said", "read"), [
    ("drive up to the read ball", "drive up to the red ball"),
    ("grab the blew cup, then turn left", "grab the blue cup, then turn left"),
])
def test_a_colour_heard_between_a_determiner_and_a_noun_is_the_colour(said: str, read: str) -> None:
    assert heard(said, PROFILE) == read


@pytest.mark.parametrize("said", ["read the label", "i read the book", "the wind blew the paper"])
def test_read_and_blew_elsewhere_are_left_alone(said: str) -> None:
    assert heard(said, PROFILE) == normalize_task(said)


@pytest.mark.parametrize(("said", "read"), [
    ("er drive for ward three meters", "drive forward 3 m"),
    ("go back wards one meter", "go backwards 1 m"),
    ("uh look up a lit tle", "look up a little"),
])
def test_a_robot_word_split_in_two_is_joined(said: str, read: str) -> None:
    assert heard(said, PROFILE) == read


@pytest.mark.parametrize(("said", "read"), [
    # A point's coordinates heard as homophones, with no comma between or with "and".
    ("go to the point for too", "go to the point 4, 2"),
    ("uh go to position for three", "go to position 4, 3"),
    ("go to the coordinates three and for", "go to the coordinates 3, 4"),
    ("go to x for y too", "go to x 4 y 2"),
    # Tens heard as a word and "tee", and a hundred's count heard as a homophone.
    ("turn left for tee five degrees", "turn left 0.7854 rad"),
    ("turn left for tee for degrees", "turn left 0.7679 rad"),
    ("turn left won hundred twenty degrees", "turn left 2.0944 rad"),
])
def test_a_number_heard_as_other_words_is_the_number(said: str, read: str) -> None:
    assert heard(said, PROFILE) == read


@pytest.mark.parametrize("said", ["go to the point to the left", "look for tee shirts", "drive twenty to the door",
                                  "go to the point for the cup"])
def test_a_homophone_that_is_no_number_stays_a_word(said: str) -> None:
    assert heard(said, PROFILE) == normalize_task(said)


@pytest.mark.parametrize("said", ["turn left", "look up a little", "pan a head left", "go back 2 metres",
                                  "look for words"])
def test_words_that_are_words_on_their_own_stay_apart(said: str) -> None:
    assert heard(said, PROFILE) == normalize_task(said)


def test_every_other_task_reads_as_normalized() -> None:
    said = "Go to the point 1, -2, then turn left thirty degrees, and look around."
    assert heard(said, PROFILE) == normalize_task(said)


def test_the_adapter_s_data_keeps_the_mishearing() -> None:
    # The model learns "write" for "right" from its data, so it still reads the ones left alone here.
    noisy = {normalize_task(asr_noise("turn right", random.Random(seed))) for seed in range(200)}
    assert any("write" in task.split() for task in noisy)


def test_a_misheard_direction_is_read_as_surely_as_the_word(adapted: Translator) -> None:
    misheard, said = adapted.translate("turn write"), adapted.translate("turn right")
    assert misheard.program == said.program == "turnright 1.5708;\n"
    assert not misheard.confirm and misheard.confidence == pytest.approx(said.confidence, abs=0.01)


def test_a_misheard_direction_is_checked_against_the_plan(adapted: Translator) -> None:
    # Unread, "write" was no direction, so a left turn around ran unasked.
    result = adapted.translate("turn around to the write")
    assert result.program.split() == ["turnright", "3.1416;"] or (
        result.confirm and any("you said right" in doubt for doubt in result.doubts))


def test_a_misheard_colour_names_the_thing(adapted: Translator) -> None:
    # Unread, "the read ball" was sent to an object named read_ball, unasked.
    assert adapted.translate("drive up to the read ball").program == "approach red_ball;\n"
