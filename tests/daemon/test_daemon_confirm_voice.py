"""A spoken yes or no answers the daemon's question, from the speech input's transcript callback on."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from agent.daemon.config import parse_config
from agent.daemon.service import Service
from agent.daemon.tasks import Task, TaskState
from agent.speech import Transcript


@pytest.fixture
def service(tmp_path: Path) -> Iterator[Service]:
    config = parse_config(f'state_dir = "{tmp_path}"\n[speech]\nenabled = false\n'
                          '[translator]\nwarmup = false\nconfirm = "always"\nconfirm_timeout = 60.0\n'
                          '[robot]\nrealtime_factor = 0.0\n')
    running = Service(config)
    running.load()
    yield running
    running.shutdown()


def _asked(service: Service) -> tuple[Task, list[Any]]:
    seen: list[Any] = []
    asked = threading.Event()

    def record(event: Any) -> None:
        seen.append(event)
        if event.name == "confirm":
            asked.set()

    service.events.subscribe(record)
    task, _ = service.submit(source="api", rsl="forward 0.3;")
    assert asked.wait(60), [e.name for e in seen]
    assert task.state is TaskState.CONFIRMING
    return task, seen


def _said(service: Service, text: str) -> None:
    service._on_transcript(Transcript(text, time.time() - 1, time.time(), "wake_word"))


def _finished(task: Task) -> None:
    deadline = time.monotonic() + 60
    while not task.state.finished:
        assert time.monotonic() < deadline, task.state
        time.sleep(0.05)


@pytest.mark.parametrize("said", ["yes", "robot, yes please", "네"])
def test_a_spoken_yes_runs_the_plan(service: Service, said: str) -> None:
    task, seen = _asked(service)
    assert service.robot.state().pose.x == pytest.approx(0.0, abs=0.01)
    _said(service, said)
    _finished(task)
    assert task.state is TaskState.DONE and task.confirmed_by == "voice"
    assert service.robot.state().pose.x == pytest.approx(0.3, abs=0.05)
    assert not any(e.name == "queued" and e.task != task.id for e in seen), "the yes became a task"


def test_a_spoken_no_cancels_it_and_nothing_moves(service: Service) -> None:
    task, _seen = _asked(service)
    _said(service, "no")
    _finished(task)
    assert task.state is TaskState.CANCELLED and "declined by voice" in task.reason
    assert service.robot.state().pose.x == pytest.approx(0.0, abs=0.01)
