"""Fixtures for the simulator tests: a fresh pybullet robot in the default scene per test."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from agent.sim.robot import SimRobot
from rsl.profile import Profile


@pytest.fixture
def robot(profile: Profile) -> Iterator[SimRobot]:
    with SimRobot(profile) as sim:
        yield sim
