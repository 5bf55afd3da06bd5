"""One real model for the whole translate test session: loading it is the slow part."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from agent.translate import Translator
from agent.translate.model_path import resolve_model
from rsl.profile import Profile


@pytest.fixture(scope="session")
def model_path() -> Path:
    return resolve_model(None)


@pytest.fixture(scope="session")
def translator(profile: Profile, model_path: Path) -> Iterator[Translator]:
    loaded = Translator.load(profile, model=str(model_path))
    yield loaded
    loaded.close()


@pytest.fixture(scope="session")
def adapted(profile: Profile) -> Iterator[Translator]:
    """The embedded model with the shipped adapter, as `nrtrans translate` loads it by default."""
    loaded = Translator.load(profile)
    yield loaded
    loaded.close()
