"""Asking before the robot moves: one open question per task, answered by a request or a spoken yes/no.

The worker thread asks and waits; the socket server's event loop and the
speech thread answer. Nothing here moves the robot: the worker runs the plan
only when `wait` returns an acceptance.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

from agent.robot import CancelToken

# How often a waiting worker looks at the task's cancel token (cancel, estop, shutdown).
_POLL_S = 0.05


@dataclass(frozen=True)
class Answer:
    accepted: bool
    by: str  # "uid 1000" or "voice"; "" when nobody answered
    reason: str  # why nothing moves, when not accepted


class Question:
    """One task's open question; `answer` may be called from any thread, once."""

    def __init__(self, task_id: str) -> None:
        self.task_id = task_id
        self._answered = threading.Event()
        self._answer: Answer | None = None
        self._lock = threading.Lock()

    def answer(self, accepted: bool, by: str) -> bool:
        """Record the answer; False when it was already answered."""
        with self._lock:
            if self._answer is not None:
                return False
            reason = "" if accepted else f"declined by {by}; nothing moved"
            self._answer = Answer(accepted, by, reason)
        self._answered.set()
        return True

    def wait(self, timeout_s: float, cancel: CancelToken) -> Answer:
        """The answer, or a refusal when `cancel` is set or `timeout_s` passes first."""
        deadline = time.monotonic() + timeout_s
        while not self._answered.wait(_POLL_S):
            if cancel.is_set():
                self.answer(False, "")
                return Answer(False, "", cancel.reason or "cancelled while waiting for an answer")
            if time.monotonic() >= deadline and self.answer(False, ""):
                return Answer(False, "", f"no answer within {timeout_s:g} s; nothing moved")
        assert self._answer is not None
        return self._answer
