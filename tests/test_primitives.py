"""`primitive_step`: every robot primitive reaches its own backend operation, with its sign and statement."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from agent.primitives import primitive_step
from agent.robot import CancelToken, Outcome
from rsl.profile import PRIMITIVES, Primitive, Profile


class Recorder:
    """Stands in for a backend: every primitive operation records its name and arguments."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, tuple[object, ...]]] = []

    def __getattr__(self, name: str) -> Callable[..., Outcome]:
        def record(*args: object) -> Outcome:
            self.calls.append((name, args))
            return Outcome.done()
        return record


TOKEN = CancelToken()
CASES = [
    ("backward", (0.5,), "drive", ("_drive", (0.5, -1.0, TOKEN, "`backward 0.5;`"))),
    ("turnright", (1.5,), "turn", ("_turn", (1.5, -1.0, TOKEN, "`turnright 1.5;`"))),
    ("lookright", (0.3,), "pan", ("_look", (-0.3, 0.0, TOKEN))),
    ("lookdown", (0.2,), "tilt", ("_look", (0.0, -0.2, TOKEN))),
    ("goto", (1.0, 2.0), "navigate", ("_navigate", (1.0, 2.0, TOKEN, "`goto 1.0, 2.0;`"))),
    ("approach", ("cup",), "approach_object", ("_approach", ("cup", TOKEN))),
    ("perceive", (), "perceive_objects", ("_perceive", (TOKEN,))),
    ("grasp", ("cup",), "grasp_object", ("_grasp", ("cup", TOKEN))),
]


def test_every_primitive_has_a_case() -> None:
    assert {primitive for _, _, primitive, _ in CASES} == set(PRIMITIVES)


@pytest.mark.parametrize(("keyword", "args", "primitive", "call"), CASES, ids=[c[2] for c in CASES])
def test_a_primitive_runs_its_operation(profile: Profile, keyword: str, args: tuple[float | str, ...],
                                        primitive: str, call: tuple[str, tuple[object, ...]]) -> None:
    skill = profile.skill(keyword)
    assert skill is not None and isinstance(skill.binding, Primitive) and skill.binding.name == primitive
    robot = Recorder()
    outcome = primitive_step(robot, skill, skill.binding, args)(TOKEN)
    assert outcome.ok and robot.calls == [call]
