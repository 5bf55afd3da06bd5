"""The shipped adapter: its card matches, and llama.cpp with it writes RSL for unseen commands."""

from __future__ import annotations

from pathlib import Path

import pytest

from agent.adapter.card import card_path, read_card, sha256_of
from agent.adapter.data import data_digest, generate
from agent.adapter.evaluate import complete, load
from agent.adapter.hygiene import eval_tasks, held_out_filter
from agent.adapter.prompt import DEFAULT_ADAPTER, PROMPT_VERSION, adapter_prompt
from agent.normalize import normalize_task
from rsl.profile import Profile

# Written for this test; none is in the training data or the eval suite.
COMMANDS = {
    "Drive forward 3.7 meters": "forward 3.7;\n",
    "rotate right 35 degrees then pick up the stapler": "turnright 0.6109;\ngrasp stapler;\n",
    "uh back up 40 centimeters": "backward 0.4;\n",
}


def test_the_card_describes_the_shipped_adapter(base_gguf: Path, profile: Profile) -> None:
    card = read_card(card_path(DEFAULT_ADAPTER))
    assert card.adapter_sha256 == sha256_of(DEFAULT_ADAPTER)
    assert card.base_model_sha256 == sha256_of(base_gguf)
    assert card.prompt_version == PROMPT_VERSION
    assert card.profile_name == profile.name
    assert card.training["final_loss"] < card.training["first_loss"]
    assert "Gemma Terms of Use" in card.licence
    # The figures train-adapter measured for it: the shipped adapter must meet the suite's targets.
    suite = card.eval["eval_suite"]
    assert suite["overall"]["n"] == 108 and suite["overall"]["verified"] == 1.0
    assert suite["overall"]["accuracy"] >= 0.95
    assert all(row["accuracy"] >= 0.85 for row in suite.values()), suite


def test_the_shipped_adapter_learned_the_data_generated_today(profile: Profile) -> None:
    # The runtime's normalizer must write what the adapter learned: a change to it, the phrasing templates
    # or the profile that changes the training data changes what the model is shown, untrained.
    data = read_card(card_path(DEFAULT_ADAPTER)).data
    pairs = generate(profile, data["pairs"], seed=data["seed"], exclude=held_out_filter(eval_tasks()))
    assert data_digest(pairs) == data["sha256"], (
        "the training data generated today is not what the shipped adapter was trained on; retrain it "
        "(nrtrans train-adapter) or keep the normalizer and the templates writing what they wrote")


@pytest.fixture(scope="module")
def adapted(base_gguf: Path):
    return load(base_gguf, DEFAULT_ADAPTER, threads=1)


@pytest.mark.parametrize("task", sorted(COMMANDS))
def test_the_adapter_writes_the_program(adapted, profile: Profile, task: str) -> None:
    got = complete(adapted, adapter_prompt(normalize_task(task), profile), max_tokens=40)
    assert got.strip() + "\n" == COMMANDS[task]
