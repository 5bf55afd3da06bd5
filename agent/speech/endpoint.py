"""Telling speech from quiet by loudness: end of speech by silence, and when to listen at all.

Vosk has its own endpointing, but its trailing-silence rules come from the
model's config and cannot be set per robot; `SilenceDetector` makes
`silence_ms` mean what it says on any model and any microphone.
"""

from __future__ import annotations

from agent.speech.audio import rms

# Below this RMS (of 32768) nothing counts as speech, however quiet the room.
MIN_SPEECH_RMS = 300.0
# Speech must be this many times louder than the running noise floor.
FLOOR_FACTOR = 3.0


class NoiseFloor:
    """The room's loudness, followed slowly, so a fan or a hum raises the bar for speech."""

    def __init__(self) -> None:
        self.floor: float | None = None

    def is_loud(self, block: bytes) -> bool:
        level = rms(block)
        loud = level > max(MIN_SPEECH_RMS, (self.floor or 0.0) * FLOOR_FACTOR)
        if not loud:
            self.floor = level if self.floor is None else 0.95 * self.floor + 0.05 * level
        return loud


class SilenceDetector:
    def __init__(self, rate: int, silence_ms: int) -> None:
        self.rate = rate
        self.silence_samples = rate * silence_ms // 1000
        self.noise = NoiseFloor()
        self.heard_speech = False
        self.quiet_samples = 0
        self.samples = 0

    def feed(self, block: bytes) -> bool:
        """Add a block of int16 samples; True once speech was heard and then `silence_ms` of quiet."""
        count = len(block) // 2
        self.samples += count
        if self.noise.is_loud(block):
            self.heard_speech = True
            self.quiet_samples = 0
        else:
            self.quiet_samples += count
        return self.heard_speech and self.quiet_samples >= self.silence_samples

    @property
    def seconds(self) -> float:
        return self.samples / self.rate
