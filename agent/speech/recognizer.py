"""Vosk models and recognisers: loading, biasing, and decoding whole files."""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from agent.speech.audio import Audio, resample
from agent.speech.lexicon import lexicon_for
from agent.speech.vocabulary import Vocabulary, build_vocabulary, supports_runtime_grammar, wanted_words
from rsl.profile import Profile

_quiet_lock = threading.Lock()
_quieted = False

# Vosk's own models are trained on 16 kHz audio.
MODEL_RATE = 16000
CHUNK_FRAMES = 4000


class SpeechModelError(RuntimeError):
    """A Vosk model that cannot be loaded, and what to do about it."""


@dataclass(frozen=True)
class LoadedModel:
    path: Path
    model: Any  # vosk.Model
    runtime_grammar: bool

    def find_word(self, word: str) -> int:
        return int(self.model.vosk_model_find_word(word))

    def vocabulary(self, profile: Profile, language: str, objects: tuple[str, ...] = (),
                   wake_words: tuple[str, ...] = ()) -> Vocabulary:
        words = wanted_words(profile, lexicon_for(language), objects, wake_words)
        return build_vocabulary(words, self.find_word)

    def recognizer(self, rate: int, grammar: str | None = None, words: bool = False) -> Any:
        """A fresh streaming recogniser; `grammar` is a JSON phrase list or None for free speech."""
        import vosk

        use_grammar = grammar is not None and self.runtime_grammar
        recognizer = vosk.KaldiRecognizer(self.model, float(rate), grammar) if use_grammar \
            else vosk.KaldiRecognizer(self.model, float(rate))
        recognizer.SetWords(words)
        return recognizer


def load_model(path: str | Path) -> LoadedModel:
    """Load a Vosk model directory (never a download: vosk is only ever given a path)."""
    try:
        import vosk
    except (ImportError, OSError) as exc:
        raise SpeechModelError(f"the vosk package cannot be loaded ({exc}); run `pip install vosk`") from None
    _quiet_vosk(vosk)
    model_path = Path(path)
    if not (model_path / "am").is_dir() or not (model_path / "conf").is_dir():
        raise SpeechModelError(f"{model_path} is not a Vosk model directory (it needs am/ and conf/). "
                               "Run `nrtrans models fetch vosk-model-small-en-us-0.15` or set the model path.")
    try:
        model = vosk.Model(str(model_path))
    except Exception as exc:
        raise SpeechModelError(f"Vosk could not load the model in {model_path}: {exc}. "
                               "The directory may be incomplete; fetch it again.") from None
    return LoadedModel(model_path, model, supports_runtime_grammar(model_path))


def _quiet_vosk(vosk: Any) -> None:
    # Kaldi logs every model load to stderr; errors still surface as exceptions.
    global _quieted
    with _quiet_lock:
        if not _quieted:
            vosk.SetLogLevel(-1)
            _quieted = True


def result_text(raw: str) -> str:
    """The words of a Vosk JSON result, without markers such as `[unk]` or `[noise]`."""
    result = json.loads(raw)
    text = str(result.get("text") or result.get("partial") or "")
    return " ".join(word for word in text.split() if not (word.startswith("[") and word.endswith("]")))


def transcribe(model: LoadedModel, audio: Audio, grammar: str | None = None,
               progress: Callable[[float], None] | None = None) -> str:
    """Decode a whole recording; several utterances come back joined by spaces.

    `progress` gets the fraction done every few seconds of audio.
    """
    samples = resample(audio, MODEL_RATE).samples.tobytes()
    recognizer = model.recognizer(MODEL_RATE, grammar)
    pieces: list[str] = []
    step = CHUNK_FRAMES * 2
    for index, start in enumerate(range(0, len(samples), step)):
        if recognizer.AcceptWaveform(samples[start:start + step]):
            pieces.append(result_text(recognizer.Result()))
        if progress is not None and index % 40 == 39:
            progress(start / len(samples))
    pieces.append(result_text(recognizer.FinalResult()))
    return " ".join(piece for piece in pieces if piece)
