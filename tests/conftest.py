"""Fixtures shared by every test area."""

from __future__ import annotations

import pytest

from rsl.profile import Profile, load_profile


@pytest.fixture(scope="session")
def profile() -> Profile:
    return load_profile()
