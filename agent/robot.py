"""The one robot interface every backend (simulator, ROS 2) implements.

A backend runs a skill by its binding (`perform`): one of the robot
primitives of `rsl.profile.PRIMITIVES` with its sign, or a ROS 2 binding. It
never looks at the skill's keyword, so a profile may call its skills anything.
Arguments come in the statement's order: floats for numbers, str for objects.
For convenience (tests, generated Python) a backend also answers
`robot.<keyword>(*args, cancel=...)` for every skill of its profile.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import Protocol, runtime_checkable

from rsl.profile import Profile, Skill


class Status(Enum):
    DONE = "done"
    FAILED = "failed"
    CANCELLED = "cancelled"


@dataclass(frozen=True)
class Outcome:
    status: Status
    reason: str = ""

    @property
    def ok(self) -> bool:
        return self.status is Status.DONE

    @classmethod
    def done(cls, reason: str = "") -> Outcome:
        return cls(Status.DONE, reason)

    @classmethod
    def failed(cls, reason: str) -> Outcome:
        return cls(Status.FAILED, reason)

    @classmethod
    def cancelled(cls, reason: str = "cancelled") -> Outcome:
        return cls(Status.CANCELLED, reason)


@dataclass(frozen=True)
class Pose:
    x: float
    y: float
    heading: float  # rad, counter-clockwise from +x


@dataclass(frozen=True)
class RobotState:
    pose: Pose
    head_pan: float
    head_tilt: float
    holding: str | None
    known_objects: tuple[tuple[str, float, float], ...] = field(default=())

    def to_dict(self) -> dict[str, object]:
        return {
            "pose": {"x": self.pose.x, "y": self.pose.y, "heading": self.pose.heading},
            "head": {"pan": self.head_pan, "tilt": self.head_tilt},
            "holding": self.holding,
            "known_objects": {name: {"x": x, "y": y} for name, x, y in self.known_objects},
        }


class CancelToken:
    """Set from any thread to stop the step in progress as soon as possible.

    Backends poll `is_set()` inside their control loops, so a cancel or an
    emergency stop takes effect during a motion, not only between steps.
    """

    def __init__(self) -> None:
        self._event = threading.Event()
        self.reason = ""

    def set(self, reason: str = "cancelled") -> None:
        self.reason = reason
        self._event.set()

    def is_set(self) -> bool:
        return self._event.is_set()

    def wait(self, timeout: float) -> bool:
        return self._event.wait(timeout)


def approach_first(profile: Profile, name: str) -> str:
    """Advice for an object out of reach, in this profile's words."""
    skill = profile.bound_to("approach_object")
    return f"`{skill.keyword} {name};` first" if skill is not None else f"drive closer to {name} first"


@runtime_checkable
class Robot(Protocol):
    """What the executor drives; a step is `perform(skill, args, cancel=...)`."""

    def perform(self, skill: Skill, args: tuple[float | str, ...], *,
                cancel: CancelToken | None = None) -> Outcome:
        """Run one step of `skill` (its binding says what to do) and say how it ended."""

    def stop(self) -> None:
        """Immediately command zero velocity and hold position."""

    def state(self) -> RobotState: ...

    def close(self) -> None: ...


class SkillCalls:
    """`robot.<keyword>(...)` for every skill of the robot's profile, as generated Python and tests call it.

    A backend mixes this in beside its `profile` and `perform`.
    """

    profile: Profile
    perform: Callable[..., Outcome]

    def __getattr__(self, name: str) -> Callable[..., Outcome]:
        profile = self.__dict__.get("profile")
        skill = profile.skill(name) if profile is not None else None
        if skill is None:
            raise AttributeError(name)

        def run(*args: float | str, cancel: CancelToken | None = None) -> Outcome:
            return self.perform(skill, args, cancel=cancel)
        return run
