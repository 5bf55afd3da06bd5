"""Events: what happened to a task, when, in order, fanned out to subscribers.

Publishing never blocks on a subscriber: each subscriber is a callback that
must only hand the event over (the socket server puts it on that client's
own bounded queue), so a slow or dead client cannot hold up the task.
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from agent.daemon.schemas import EVENT_FIELDS, VERSION

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Event:
    name: str
    task: str | None
    ts: float
    seq: int
    data: dict[str, Any] = field(default_factory=dict)

    def frame(self) -> dict[str, Any]:
        return {
            "v": VERSION,
            "type": "event",
            "event": self.name,
            "task": self.task,
            "ts": self.ts,
            "seq": self.seq,
            **self.data,
        }


Subscriber = Callable[[Event], None]


class EventBus:
    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._seq = itertools.count(1)
        self._subscribers: dict[int, tuple[Subscriber, str | None]] = {}
        self._keys = itertools.count(1)

    def subscribe(self, callback: Subscriber, task: str | None = None) -> int:
        """Deliver every event (or only `task`'s) to `callback`; returns a key for `unsubscribe`."""
        with self._lock:
            key = next(self._keys)
            self._subscribers[key] = (callback, task)
        return key

    def unsubscribe(self, key: int) -> None:
        with self._lock:
            self._subscribers.pop(key, None)

    def publish(self, name: str, task: str | None, **data: Any) -> Event:
        assert name in EVENT_FIELDS, name
        with self._lock:
            # Numbered and stamped under the lock so `seq` order is delivery order.
            event = Event(name, task, time.time(), next(self._seq), data)
            targets = [cb for cb, only in self._subscribers.values() if only is None or only == task]
            for callback in targets:
                try:
                    callback(event)
                except Exception:
                    log.exception("event subscriber failed on %s", name)
        return event
