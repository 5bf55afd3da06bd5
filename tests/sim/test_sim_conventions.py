"""Every convention the shipped profile teaches runs on the shipped robot as it says, without a clamp.

On open floor: this is about what the robot can do (joint limits, speeds, timeouts), not about
what stands in the default room (`forward 5` from the start would meet the table).
"""

from __future__ import annotations

import pytest

from agent.executor import execute
from agent.sim.robot import SimRobot
from agent.sim.scene import parse_scene
from rsl.compiler import compile_program
from rsl.profile import Profile, load_profile

CONVENTIONS = load_profile().conventions
OPEN_FLOOR = "[start]\nx = 0.0\ny = 0.0\nheading = 0.0\n"


@pytest.mark.parametrize("convention", CONVENTIONS, ids=lambda c: c.phrase.replace(" ", "-"))
def test_the_conventions_program_runs_on_the_simulator(convention, profile: Profile) -> None:
    compiled = compile_program(convention.program, profile)
    assert compiled.ok, [d.message for d in compiled.diagnostics]
    with SimRobot(profile, parse_scene(OPEN_FLOOR, "open floor")) as robot:
        result = execute(compiled.plan, robot, profile)
    assert result.ok, result.outcomes
    # A clamp or a detour means the convention asks for what this robot cannot do as written.
    notes = [o.reason for o in result.outcomes if "limit" in o.reason]
    assert notes == [], notes
