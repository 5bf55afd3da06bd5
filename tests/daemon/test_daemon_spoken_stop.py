"""A spoken stop, from the speech input's transcript callback on: the robot stops and no task is made.

Recognition is left out on purpose: with espeak's voice the small Korean model
sometimes hears "정지" (stop) as "전진" (forward), which made an audio test of
this flaky; test_daemon_voice covers audio to transcript.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from agent.daemon.config import parse_config
from agent.daemon.service import Service
from agent.daemon.tasks import TaskState
from agent.speech import Transcript


@pytest.fixture
def service(tmp_path: Path) -> Iterator[Service]:
    config = parse_config(f'state_dir = "{tmp_path}"\n[speech]\nenabled = false\n[translator]\nwarmup = false\n')
    running = Service(config)
    running.load()
    yield running
    running.shutdown()


def _events(service: Service) -> tuple[list[Any], threading.Event]:
    seen: list[Any] = []
    executing = threading.Event()

    def record(event: Any) -> None:
        seen.append(event)
        if event.name == "executing":
            executing.set()

    service.events.subscribe(record)
    return seen, executing


@pytest.mark.parametrize("said", ["stop", "robot, stop right now!", "정지"])
def test_a_spoken_stop_halts_the_drive_and_cancels_the_queue(service: Service, said: str) -> None:
    seen, executing = _events(service)
    running, _ = service.submit(source="api", rsl="forward 5;")
    queued, _ = service.submit(source="api", rsl="turnleft 1;")
    assert executing.wait(30), seen
    time.sleep(0.3)
    service._on_transcript(Transcript(said, time.time() - 1, time.time(), "wake_word"))
    stop = next(e for e in seen if e.name == "speech")
    assert stop.data["state"] == "stop" and sorted(stop.data["detail"]["cancelled"]) == sorted([running.id, queued.id])
    deadline = time.monotonic() + 10
    while not running.state.finished:
        assert time.monotonic() < deadline, running.state
        time.sleep(0.05)
    assert running.state is TaskState.CANCELLED and "stopped by voice" in running.reason
    assert queued.state is TaskState.CANCELLED
    x = service.robot.state().pose.x
    time.sleep(0.5)
    assert service.robot.state().pose.x == pytest.approx(x, abs=0.01), "the robot kept moving"
    assert x < 4.5, "the robot stopped before the end of the drive"
    # Nothing latched, and the stop made no task: the next task runs.
    assert service.daemon_status()["state"] != "estopped"
    assert not any(e.name in ("heard", "queued") and e.task not in (running.id, queued.id) for e in seen)


def test_a_task_that_mentions_stopping_is_still_a_task(service: Service) -> None:
    seen, _ = _events(service)
    service._on_transcript(Transcript("drive forward 0.2 meters and stop", time.time() - 1, time.time(), "wake_word"))
    assert any(e.name == "heard" for e in seen) and not any(e.name == "speech" for e in seen)
