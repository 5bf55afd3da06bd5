"""Barge-in: a listener that hears only the stop words, while the robot moves, without the wake word.

The task recogniser decodes a whole sentence against the task vocabulary, and
with a small model it can hear "정지" (stop) as "전진" (forward). The stop
spotter is a second Vosk recogniser with a grammar of the stop words, so the
only thing it can ever report is a stop; it needs no wake word and answers on
the partial result, while the word is still being said. Its grammar also
holds a filler so that other speech does not land on a stop word: `[unk]`
where the model has it, otherwise the task words as decoys. A stop word
counts only with Vosk's word confidence at or above a threshold (the
`stop_threshold` setting; bench/bench_stop_spotter.py measures hits and
false alarms per threshold).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from agent.speech.spotting import HANGOVER_S, SpeechGate, TimedRecognizer, keyword_grammar
from agent.speech.vocabulary import Vocabulary


@dataclass(frozen=True)
class StopHeard:
    word: str
    confidence: float


def stop_grammar(stop_words: Sequence[str], vocabulary: Vocabulary) -> str:
    """The stop words and their filler: `[unk]`, or every other task word as a decoy."""
    return keyword_grammar(stop_words, vocabulary)


class StopSpotter:
    """Feed it audio blocks; `feed` returns a `StopHeard` when a stop word was said with enough confidence."""

    def __init__(self, recognizer: TimedRecognizer, stop_words: Sequence[str], threshold: float,
                 hangover_s: float = HANGOVER_S) -> None:
        self.recognizer = recognizer
        self.stop_words = frozenset(w.lower() for w in stop_words)
        self.threshold = threshold
        self.gate = SpeechGate(recognizer.rate, hangover_s)

    @property
    def active(self) -> bool:
        """Within a stretch of speech."""
        return self.gate.active

    def feed(self, block: bytes) -> StopHeard | None:
        for piece in self.gate.admit(block):
            heard = self._accept(piece)
            if heard is not None:
                return heard
        if self.gate.ended:
            self.gate.close()
            return self._judge(self.recognizer.result(False))
        return None

    def reset(self) -> None:
        """Forget the stretch in progress (the robot stopped moving, say)."""
        self.recognizer.reset()
        self.gate.reset()

    def _accept(self, block: bytes) -> StopHeard | None:
        if self.recognizer.accept(block):
            return self._judge(self.recognizer.result(True))
        partial = str(self.recognizer.partial().get("partial", "")).lower().split()
        if not self.stop_words.intersection(partial):
            return None
        # Closing the stretch now gives the word's confidence while the person is still speaking.
        return self._judge(self.recognizer.result(False))

    def _judge(self, result: dict[str, Any]) -> StopHeard | None:
        for word in result.get("result") or []:
            text, confidence = str(word.get("word", "")).lower(), float(word.get("conf", 0.0))
            if text in self.stop_words and confidence >= self.threshold:
                return StopHeard(text, confidence)
        return None
