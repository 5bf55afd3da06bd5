"""Every convention the shipped profile teaches runs on the shipped robot as it says, without a clamp.

On open floor: this is about what the robot can do (joint limits, speeds, timeouts), not about
what stands in the default room (`forward 5` from the start would meet the table). An object a
convention's program names ("go get": `approach cup; grasp cup; ...`) stands on a table 2 m ahead.
"""

from __future__ import annotations

import pytest

from agent.executor import execute
from agent.sim.robot import SimRobot
from agent.sim.scene import parse_scene
from rsl.compiler import compile_program
from rsl.plan import ObjectRef
from rsl.profile import Profile, load_profile

CONVENTIONS = load_profile().conventions
OPEN_FLOOR = "[start]\nx = 0.0\ny = 0.0\nheading = 0.0\n"


@pytest.mark.parametrize("convention", CONVENTIONS, ids=lambda c: c.phrase.replace(" ", "-"))
def test_the_conventions_program_runs_on_the_simulator(convention, profile: Profile) -> None:
    compiled = compile_program(convention.program, profile)
    assert compiled.ok, [d.message for d in compiled.diagnostics]
    named = dict.fromkeys(a.name for c in compiled.plan for a in c.args if isinstance(a, ObjectRef))
    objects = "".join(f'[[objects]]\nname = "{name}"\nshape = "cylinder"\nx = 1.68\ny = {0.25 * i}\nz = 0.81\n'
                      f'size = [0.08, 0.08, 0.12]\nmass = 0.2\n' for i, name in enumerate(named))
    if named:
        objects += ('[[objects]]\nname = "stand"\nkind = "furniture"\nshape = "box"\nx = 2.0\ny = 0.0\n'
                    'size = [0.8, 1.2, 0.75]\nmass = 25.0\n')
    with SimRobot(profile, parse_scene(OPEN_FLOOR + objects, "open floor")) as robot:
        if named:  # seen first, as the daemon's world checks would have it look
            perceive = profile.bound_to("perceive_objects")
            assert perceive is not None
            looked = compile_program(f"{perceive.keyword};", profile).plan
            assert looked is not None and execute(looked, robot, profile).ok
        result = execute(compiled.plan, robot, profile)
    assert result.ok, result.outcomes
    # A clamp or a detour means the convention asks for what this robot cannot do as written.
    notes = [o.reason for o in result.outcomes if "limit" in o.reason]
    assert notes == [], notes
