"""Tasks and the bounded queue in front of the robot.

One task moves the robot at a time; the rest wait in a bounded queue, and a
submit beyond its bound is refused with `Busy` rather than dropped.
"""

from __future__ import annotations

import threading
import time
import uuid
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from agent.robot import CancelToken


class TaskState(Enum):
    QUEUED = "queued"
    TRANSLATING = "translating"
    CONFIRMING = "confirming"  # verified, waiting for the person to answer the `confirm` question
    EXECUTING = "executing"
    DONE = "done"
    FAILED = "failed"
    REJECTED = "rejected"
    CANCELLED = "cancelled"
    INTERRUPTED = "interrupted"

    @property
    def finished(self) -> bool:
        return self in _FINISHED


_FINISHED = {TaskState.DONE, TaskState.FAILED, TaskState.REJECTED, TaskState.CANCELLED, TaskState.INTERRUPTED}


@dataclass(frozen=True)
class Peer:
    """Who submitted a task, as the kernel reports it (SO_PEERCRED)."""

    pid: int
    uid: int
    gid: int

    def to_dict(self) -> dict[str, int]:
        return {"pid": self.pid, "uid": self.uid, "gid": self.gid}


@dataclass(eq=False)
class Task:
    """A live task; only the worker thread changes it once it is taken off the queue."""

    source: str
    text: str | None = None
    rsl: str | None = None
    peer: Peer | None = None
    transcript: dict[str, Any] | None = None
    id: str = field(default_factory=lambda: uuid.uuid4().hex[:12])
    created: float = field(default_factory=time.time)
    state: TaskState = TaskState.QUEUED
    attempts: list[dict[str, Any]] = field(default_factory=list)
    program: str | None = None
    plan: list[dict[str, Any]] | None = None
    steps: list[dict[str, Any]] = field(default_factory=list)
    reason: str = ""
    model: str | None = None
    explanation: str = ""
    confidence: float | None = None
    confirmed_by: str | None = None  # who let an asked plan run: "uid N" or "voice"
    doubts: list[str] = field(default_factory=list)  # why the translation is unsure
    timings_ms: dict[str, float] = field(default_factory=dict)
    cancel: CancelToken = field(default_factory=CancelToken, repr=False)

    def record(self) -> dict[str, Any]:
        """The task as JSON data: the audit record and the `status` reply."""
        return {
            "task": self.id,
            "state": self.state.value,
            "source": self.source,
            "peer": self.peer.to_dict() if self.peer else None,
            "created": self.created,
            "transcript": self.transcript,
            "text": self.text,
            "rsl": self.rsl,
            "attempts": list(self.attempts),
            "program": self.program,
            "plan": self.plan,
            "steps": list(self.steps),
            "reason": self.reason,
            "model": self.model,
            "explanation": self.explanation,
            "confidence": self.confidence,
            "confirmed_by": self.confirmed_by,
            "doubts": list(self.doubts),
            "timings_ms": dict(self.timings_ms),
        }

    def mark(self, name: str, since: float) -> None:
        self.timings_ms[name] = round((time.monotonic() - since) * 1000.0, 3)


class Busy(Exception):
    pass


class TaskQueue:
    def __init__(self, capacity: int) -> None:
        self.capacity = capacity
        self._items: deque[Task] = deque()
        self._cond = threading.Condition()
        self._closed = False

    def put(self, task: Task, on_accept: Callable[[int], None] | None = None) -> int:
        """Queue `task`; returns how many wait ahead of it. Raises `Busy` when full.

        `on_accept(position)` runs before the worker can see the task, so whatever it
        records or announces comes before anything the worker does with it.
        """
        with self._cond:
            if self._closed:
                raise Busy("the daemon is shutting down")
            if len(self._items) >= self.capacity:
                raise Busy(f"{len(self._items)} tasks are already waiting (the limit is {self.capacity})")
            position = len(self._items)
            if on_accept is not None:
                on_accept(position)
            self._items.append(task)
            self._cond.notify()
            return position

    def get(self) -> Task | None:
        """The next task, waiting for one; None once the queue is closed."""
        with self._cond:
            while not self._items and not self._closed:
                self._cond.wait()
            if self._closed:
                return None
            return self._items.popleft()

    def remove(self, task_id: str) -> Task | None:
        with self._cond:
            for task in self._items:
                if task.id == task_id:
                    self._items.remove(task)
                    return task
        return None

    def drain(self) -> list[Task]:
        with self._cond:
            tasks = list(self._items)
            self._items.clear()
            return tasks

    def position(self, task_id: str) -> int | None:
        with self._cond:
            for index, task in enumerate(self._items):
                if task.id == task_id:
                    return index
        return None

    def __len__(self) -> int:
        with self._cond:
            return len(self._items)

    def close(self) -> None:
        with self._cond:
            self._closed = True
            self._cond.notify_all()
