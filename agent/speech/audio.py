"""Reading WAV files and bringing audio to 16-bit mono at the recogniser's rate."""

from __future__ import annotations

import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np


class AudioFileError(ValueError):
    """A file that is not audio nrtrans can read, with what to do instead."""


@dataclass(frozen=True)
class Audio:
    samples: np.ndarray  # int16, mono
    rate: int

    @property
    def seconds(self) -> float:
        return len(self.samples) / self.rate if self.rate else 0.0


def read_wav(path: str | Path) -> Audio:
    """A PCM WAV file of any width, rate and channel count, as int16 mono."""
    source = Path(path)
    try:
        with wave.open(str(source), "rb") as handle:
            width = handle.getsampwidth()
            channels = handle.getnchannels()
            rate = handle.getframerate()
            raw = handle.readframes(handle.getnframes())
    except FileNotFoundError:
        raise AudioFileError(f"{source}: no such file") from None
    except IsADirectoryError:
        raise AudioFileError(f"{source} is a directory, not a WAV file") from None
    except (wave.Error, EOFError) as exc:
        raise AudioFileError(
            f"{source} is not a PCM WAV file ({exc}). Convert it first, for example "
            f"`ffmpeg -i {source.name} -ar 16000 -ac 1 out.wav` or `sox {source.name} -r 16000 -c 1 out.wav`."
        ) from None
    if width == 1:
        data = (np.frombuffer(raw, dtype=np.uint8).astype(np.int32) - 128) << 8
    elif width == 2:
        data = np.frombuffer(raw, dtype="<i2").astype(np.int32)
    elif width == 3:
        bytes3 = np.frombuffer(raw, dtype=np.uint8).reshape(-1, 3).astype(np.int32)
        data = ((bytes3[:, 0] << 8) | (bytes3[:, 1] << 16) | (bytes3[:, 2] << 24)) >> 16
    elif width == 4:
        data = np.frombuffer(raw, dtype="<i4").astype(np.int64) >> 16
    else:
        raise AudioFileError(f"{source}: {8 * width}-bit samples are not supported; use 16-bit PCM")
    if channels > 1:
        data = data[: len(data) - len(data) % channels].reshape(-1, channels).mean(axis=1)
    return Audio(np.clip(data, -32768, 32767).astype(np.int16), rate)


def resample(audio: Audio, rate: int) -> Audio:
    """Linear-interpolation resampling, low-passed first when going down, which is enough for ASR."""
    if audio.rate == rate or len(audio.samples) == 0:
        return Audio(audio.samples, rate)
    data: np.ndarray = audio.samples.astype(np.float64)
    if rate < audio.rate:
        # A box filter as wide as the decimation step keeps most aliasing out.
        width = max(1, round(audio.rate / rate))
        if width > 1:
            data = np.convolve(data, np.ones(width) / width, mode="same")
    count = round(len(data) * rate / audio.rate)
    positions = np.linspace(0, len(data) - 1, count)
    resampled = np.interp(positions, np.arange(len(data)), data)
    return Audio(np.clip(np.round(resampled), -32768, 32767).astype(np.int16), rate)


def rms(block: bytes | np.ndarray) -> float:
    """Loudness of a block of int16 samples (0 to 32768)."""
    samples = np.frombuffer(block, dtype=np.int16) if isinstance(block, bytes | bytearray) else block
    if len(samples) == 0:
        return 0.0
    return float(np.sqrt(np.mean(samples.astype(np.float64) ** 2)))
