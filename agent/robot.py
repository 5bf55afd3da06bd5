"""The one robot interface every backend (simulator, ROS 2) implements.

A backend has one method per skill in the robot profile, named after the
skill's keyword, taking the statement's arguments in order (floats for
numbers, str for objects) plus a keyword-only `cancel` token, and returning
an `Outcome`. Skills are data, so a backend is looked up by keyword at run
time rather than through a fixed list of abstract methods.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from enum import Enum
from typing import Protocol, runtime_checkable


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


@runtime_checkable
class Robot(Protocol):
    """Skill methods are looked up by keyword: `getattr(robot, command.skill)`."""

    def stop(self) -> None:
        """Immediately command zero velocity and hold position."""

    def state(self) -> RobotState: ...

    def close(self) -> None: ...
