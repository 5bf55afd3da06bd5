"""The speech input's settings and the records it emits."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Literal

# barge_in: the stop listener heard a stop word while the robot moved; the text is only ever that word.
TranscriptSource = Literal["wake_word", "push_to_talk", "file", "barge_in"]


class SpeechConfigError(ValueError):
    """A speech setting that cannot be used; says which and what is allowed."""


@dataclass(frozen=True)
class SpeechConfig:
    """Settings of the speech input, as given in the daemon's `[speech.options]` table."""

    enabled: bool = True
    # A model name from `nrtrans models list`, a Vosk model directory, or
    # None for the manifest's default Vosk model.
    model: str | None = None
    # A sounddevice input: index, name substring, or None for the default.
    device: str | int | None = None
    sample_rate: int = 16000
    # Which lexicon biases recognition; must match the model's language.
    language: str = "en"
    # Said before a task; an empty list means push-to-talk only.
    wake_words: tuple[str, ...] = ("robot",)
    # Quiet after speech that ends the utterance. It is most of the delay
    # from end of speech to transcript (see docs/speech.md).
    silence_ms: int = 500
    max_utterance_s: float = 15.0
    # After push-to-talk or a lone wake word: how long to wait for speech.
    no_speech_timeout_s: float = 5.0
    # Restrict recognition to the profile's words, objects and numbers when
    # the model supports runtime grammars (see docs/speech.md for the measurement).
    grammar_bias: bool = True
    # Object names to bias toward, besides those added with `set_objects`.
    objects: tuple[str, ...] = ()
    # Robot profile file; None for the default profile.
    profile: str | None = None
    # How often to try again to open a missing or lost audio device.
    retry_s: float = 5.0
    # Say each step aloud through espeak-ng ("moving forward two meters").
    feedback: bool = False
    feedback_voice: str = "en-us"
    # While the robot moves, listen for the stop words alone, without the wake word (docs/speech.md).
    barge_in: bool = True
    # Vosk word confidence a stop word needs to stop the robot (bench/bench_stop_spotter.py).
    stop_threshold: float = 0.3

    @classmethod
    def from_dict(cls, options: dict[str, Any]) -> SpeechConfig:
        """Build from config-file values, with errors that name the setting."""
        fields = {f.name: f for f in dataclasses.fields(cls)}
        unknown = sorted(set(options) - set(fields))
        if unknown:
            raise SpeechConfigError(f"unknown speech setting(s) {', '.join(unknown)}; "
                                    f"the settings are: {', '.join(fields)}")
        values: dict[str, Any] = {}
        for name, value in options.items():
            if name in ("wake_words", "objects"):
                if isinstance(value, str) or not all(isinstance(v, str) for v in value):
                    raise SpeechConfigError(f"speech.{name} must be a list of strings, like [\"robot\"]")
                value = tuple(value)
            values[name] = value
        config = cls(**values)
        config.check()
        return config

    def check(self) -> None:
        checks = (
            (isinstance(self.enabled, bool), "enabled must be true or false"),
            (isinstance(self.grammar_bias, bool), "grammar_bias must be true or false"),
            (isinstance(self.feedback, bool), "feedback must be true or false"),
            (isinstance(self.barge_in, bool), "barge_in must be true or false"),
            (isinstance(self.stop_threshold, int | float) and 0.0 <= self.stop_threshold <= 1.0,
             "stop_threshold must be from 0 to 1"),
            (isinstance(self.feedback_voice, str) and bool(self.feedback_voice),
             "feedback_voice must be an espeak-ng voice name, like \"en-us\""),
            (self.model is None or isinstance(self.model, str), "model must be a name or a path"),
            (self.device is None or isinstance(self.device, str | int), "device must be a name or an index"),
            (isinstance(self.sample_rate, int) and 8000 <= self.sample_rate <= 48000,
             "sample_rate must be an integer from 8000 to 48000"),
            (isinstance(self.silence_ms, int) and 100 <= self.silence_ms <= 10000,
             "silence_ms must be an integer from 100 to 10000"),
            (isinstance(self.max_utterance_s, int | float) and 1 <= self.max_utterance_s <= 120,
             "max_utterance_s must be from 1 to 120 seconds"),
            (isinstance(self.no_speech_timeout_s, int | float) and 0.5 <= self.no_speech_timeout_s <= 60,
             "no_speech_timeout_s must be from 0.5 to 60 seconds"),
            (isinstance(self.retry_s, int | float) and 0.1 <= self.retry_s <= 600,
             "retry_s must be from 0.1 to 600 seconds"),
        )
        for ok, message in checks:
            if not ok:
                raise SpeechConfigError(f"speech.{message}")


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
