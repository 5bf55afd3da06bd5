"""The speech input's settings and the records it emits."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Literal

from rsl.settings import read_settings, setting

# barge_in: the stop listener heard a stop word while the robot moved; the text is only ever that word.
TranscriptSource = Literal["wake_word", "push_to_talk", "file", "barge_in"]


class SpeechConfigError(ValueError):
    """A speech setting that cannot be used; says which and what is allowed."""


@dataclass(frozen=True)
class SpeechConfig:
    """Settings of the speech input, as given in the daemon's `[speech.options]` table."""

    enabled: bool = setting(True, doc="listen at all")
    model: str | None = setting(None, doc=(
        "a model name from `nrtrans models list`, a Vosk model directory, or none for the manifest's "
        "default Vosk model"))
    device: str | int | None = setting(None, doc="a sounddevice input: index, name substring, or none for the default")
    sample_rate: int = setting(16000, min=8000, max=48000, doc="the audio device's sample rate, Hz")
    language: str = setting("en", nonempty=True, doc="which lexicon biases recognition; must match the model's")
    wake_words: tuple[str, ...] = setting(("robot",), doc="said before a task; an empty list means push-to-talk only")
    silence_ms: int = setting(500, min=100, max=10000, doc=(
        "quiet after speech that ends the utterance; most of the delay from end of speech to transcript "
        "(docs/speech.md)"))
    max_utterance_s: float = setting(15.0, min=1, max=120, doc="longest utterance, seconds")
    no_speech_timeout_s: float = setting(5.0, min=0.5, max=60, doc=(
        "after push-to-talk or a lone wake word: how long to wait for speech, seconds"))
    grammar_bias: bool = setting(True, doc=(
        "restrict recognition to the profile's words, objects and numbers when the model supports runtime "
        "grammars (docs/speech.md has the measurement)"))
    objects: tuple[str, ...] = setting((), doc="object names to bias toward, besides those added with `set_objects`")
    profile: str | None = setting(None, doc="robot profile file; none for the default profile")
    retry_s: float = setting(5.0, min=0.1, max=600, doc="how often to try again to open a missing or lost device")
    feedback: bool = setting(False, doc="say each step aloud through espeak-ng (\"moving forward two meters\")")
    feedback_voice: str = setting("en-us", nonempty=True, doc="the espeak-ng voice, like \"en-us\"")
    barge_in: bool = setting(True, doc=(
        "while the robot moves, listen for the stop words alone, without the wake word (docs/speech.md)"))
    stop_threshold: float = setting(0.3, min=0.0, max=1.0, doc=(
        "Vosk word confidence a stop word needs to stop the robot (bench/bench_stop_spotter.py)"))

    @classmethod
    def from_dict(cls, options: dict[str, Any]) -> SpeechConfig:
        """Build from config-file values, with errors that name the setting."""
        return read_settings(cls, options, error=SpeechConfigError, prefix="speech.", docs="docs/speech.md")


@dataclass(frozen=True)
class Transcript:
    """What a person said, without the wake word."""

    text: str
    started_at: float  # time.time() when the utterance began
    ended_at: float
    source: TranscriptSource

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class SpeechEvent:
    """Something the speech input did or ran into, for the event stream and logs.

    kinds: ready, wake, listening, heard, stop_heard, no_speech, empty,
    device_error, device_lost, model_error, stopped.
    """

    kind: str
    at: float
    detail: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "at": self.at, **self.detail}
