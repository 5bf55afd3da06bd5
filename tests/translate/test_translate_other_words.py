"""A convention's phrase said in other words is read as the phrase (agent/translate/other_words.py)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from agent.normalize import normalize_task
from agent.translate import Translator
from agent.translate.misheard import heard
from rsl.profile import load_profile, parse_profile

PROFILE = load_profile()


@pytest.mark.parametrize(("said", "read"), [
    ("turn left slightly", "turn left a little"),
    ("back up just a bit", "back up a little"),
    ("turn a tad to the left, then look up ever so slightly", "turn a little to the left, then look up a little"),
    ("go a long way forward", "go a long distance forward"),
    # "write" before an amount in other words is the way, as before the phrase.
    ("look write just a tiny bit", "look right a little"),
])
def test_other_words_for_a_convention_s_phrase_are_read_as_the_phrase(said: str, read: str) -> None:
    assert heard(said, PROFILE) == read


@pytest.mark.parametrize("said", [
    # A phrase of its own that holds another's word, a word that describes a thing, and a remark: read as
    # "a long distance", the model drove 5 m for it.
    "go a bit further",
    "pick up the slightly bigger box",
    "that was a long way to go, wasn't it?",
])
def test_a_phrase_of_its_own_and_a_thing_s_description_stay(said: str) -> None:
    assert heard(said, PROFILE) == normalize_task(said)


def test_the_words_come_from_the_profile() -> None:
    text = Path(PROFILE.source).read_text(encoding="utf-8")
    without = parse_profile(re.sub(r"\nalso = \[[^\]]*\]", "", text))
    assert all(not c.also for c in without.conventions)
    assert heard("turn left slightly", without) == "turn left slightly"


def test_an_amount_said_in_other_words_runs_as_the_convention_s(adapted: Translator) -> None:
    # Read as it stood, "slightly" ran unasked as a quarter turn.
    result = adapted.translate("rotate right a smidge")
    assert result.program == "turnright 0.2618;\n"
