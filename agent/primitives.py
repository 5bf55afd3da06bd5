"""Which of a backend's operations runs a skill bound to a robot primitive, and with what.

Every backend implements the operations of `Primitives`; `primitive_step`
turns a skill's binding and a statement's arguments into the call, so a new
primitive in `rsl.profile.PRIMITIVES` is wired here once for all backends.
Each backend runs the call inside its own wrapper (cancel, stop, failures).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from agent.executor import navigate_point
from agent.robot import CancelToken, Outcome
from rsl.profile import Primitive, Skill

Step = Callable[[CancelToken], Outcome]


class Primitives(Protocol):
    """The primitive operations of a backend.

    The names start with an underscore because `SkillCalls` answers every other
    attribute name a skill keyword may have. `what` is the statement, for
    failure messages; a sign of -1 reverses a motion.
    """

    def _drive(self, distance: float, sign: float, token: CancelToken, what: str, /) -> Outcome: ...

    def _turn(self, angle: float, sign: float, token: CancelToken, what: str, /) -> Outcome: ...

    def _look(self, pan_by: float, tilt_by: float, token: CancelToken, /) -> Outcome: ...

    def _navigate(self, x: float, y: float, token: CancelToken, what: str, /) -> Outcome: ...

    def _approach(self, name: str, token: CancelToken, /) -> Outcome: ...

    def _perceive(self, token: CancelToken, /) -> Outcome: ...

    def _grasp(self, name: str, token: CancelToken, /) -> Outcome: ...


def primitive_step(robot: Primitives, skill: Skill, binding: Primitive, args: tuple[float | str, ...]) -> Step:
    """The step that runs `skill`, bound to `binding`, with `args` on `robot`.

    But for a navigate point, the arguments are read inside the step, so a bad
    one fails within the backend's wrapper.
    """
    sign, statement = binding.sign, f"`{skill.keyword}{' ' if args else ''}{', '.join(map(str, args))};`"
    if binding.name == "drive":
        return lambda token: robot._drive(float(args[0]), sign, token, statement)
    if binding.name == "turn":
        return lambda token: robot._turn(float(args[0]), sign, token, statement)
    if binding.name == "pan":
        return lambda token: robot._look(sign * float(args[0]), 0.0, token)
    if binding.name == "tilt":
        return lambda token: robot._look(0.0, sign * float(args[0]), token)
    if binding.name == "navigate":
        x, y = navigate_point(skill, [float(a) for a in args])
        return lambda token: robot._navigate(x, y, token, statement)
    if binding.name == "approach_object":
        return lambda token: robot._approach(str(args[0]), token)
    if binding.name == "perceive_objects":
        return robot._perceive
    return lambda token: robot._grasp(str(args[0]), token)
