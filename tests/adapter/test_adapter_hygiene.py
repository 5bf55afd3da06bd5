"""No eval-suite task, nor a close paraphrase of one, may be in the training data."""

from __future__ import annotations

import difflib
import re

import pytest

from agent.adapter.data import generate
from agent.adapter.hygiene import eval_tasks, held_out_filter, is_close
from agent.normalize import normalize_task
from rsl.profile import Profile

TRAIN_PAIRS = 5000  # what `nrtrans train-adapter` uses by default


def _plain(text: str) -> str:
    return " ".join(re.sub(r"[^a-z0-9.\- ]", " ", text.lower()).split())


@pytest.fixture(scope="module")
def suite() -> list[str]:
    tasks = eval_tasks()
    if not tasks:
        pytest.skip("agent/evalsuite/suite.toml is missing: nothing to keep out of the training data")
    return tasks


def test_training_data_holds_no_eval_task_or_close_paraphrase(profile: Profile, suite: list[str]) -> None:
    pairs = generate(profile, TRAIN_PAIRS, seed=0, exclude=held_out_filter(suite))
    normalized_suite = [normalize_task(t) for t in suite]
    plain_suite = [_plain(t) for t in suite]
    for pair in pairs:
        for reference, plain in zip(normalized_suite, plain_suite, strict=True):
            assert pair.normalized != reference, pair
            assert not is_close(pair.normalized, reference), (pair, reference)
            # An independent check on the raw, unnormalized text.
            raw = difflib.SequenceMatcher(None, _plain(pair.task), plain, autojunk=False)
            assert raw.quick_ratio() <= 0.95 or raw.ratio() <= 0.95, (pair, plain)


def test_the_filter_catches_exact_and_paraphrased_tasks(suite: list[str]) -> None:
    excluded = held_out_filter(suite)
    for task in suite[:20]:
        assert excluded(normalize_task(task))
        assert excluded(normalize_task(task.lower().rstrip(".") + "!"))
    assert not excluded("perceive, then grasp the zebra, then go to 9, 9, then look up 1.2 rad")
