"""Fixtures for the speech tests: a private PulseAudio with a null sink, espeak-ng audio, the Korean model."""

from __future__ import annotations

import queue
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.speech.pulse import PACKAGES, VirtualMic, missing_tools, speak


@pytest.fixture(scope="session")
def audio_tools() -> None:
    missing = missing_tools()
    if missing:
        pytest.fail(f"the speech tests need {', '.join(missing)}: apt-get install -y {PACKAGES}")


@pytest.fixture(scope="module")
def mic(audio_tools: None) -> Iterator[VirtualMic]:
    with VirtualMic() as virtual:
        yield virtual


@pytest.fixture(scope="session")
def voice_dir(tmp_path_factory: pytest.TempPathFactory, audio_tools: None) -> Path:
    return tmp_path_factory.mktemp("voices")


@pytest.fixture(scope="session")
def say(voice_dir: Path):
    """`say("원점 돌아가")` -> a WAV of espeak-ng saying it in Korean (cached per text)."""
    cache: dict[tuple[str, str], Path] = {}

    def make(text: str, voice: str = "ko") -> Path:
        key = (text, voice)
        if key not in cache:
            cache[key] = speak(text, voice_dir / f"{len(cache)}.wav", voice)
        return cache[key]

    return make


class Collector:
    """Receives transcripts and events from a SpeechInput thread."""

    def __init__(self) -> None:
        self.transcripts: queue.Queue = queue.Queue()
        self.events: list = []

    def on_transcript(self, transcript) -> None:
        self.transcripts.put(transcript)

    def on_event(self, event) -> None:
        self.events.append(event)

    def kinds(self) -> list[str]:
        return [e.kind for e in self.events]


@pytest.fixture
def collector() -> Collector:
    return Collector()
