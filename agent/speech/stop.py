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

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from agent.speech.endpoint import NoiseFloor
from agent.speech.spotting import HANGOVER_S, LEAD_IN_S, TimedRecognizer, keyword_grammar
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
        self.noise = NoiseFloor()
        self.lead: deque[bytes] = deque()
        self.hangover_samples = int(hangover_s * recognizer.rate)
        self.active = False
        self.quiet_samples = 0

    def feed(self, block: bytes) -> StopHeard | None:
        # Gated by loudness like the wake spotter: hours of quiet drift Vosk's adaptation and cost CPU.
        loud = self.noise.is_loud(block)
        if not self.active:
            if not loud:
                self.lead.append(block)
                while sum(len(b) for b in self.lead) // 2 > LEAD_IN_S * self.recognizer.rate:
                    self.lead.popleft()
                return None
            self.active = True
            self.quiet_samples = 0
            lead, self.lead = list(self.lead), deque()
            for earlier in lead:
                heard = self._accept(earlier)
                if heard is not None:
                    return heard
        self.quiet_samples = 0 if loud else self.quiet_samples + len(block) // 2
        heard = self._accept(block)
        if heard is None and self.quiet_samples >= self.hangover_samples:
            heard = self._judge(self.recognizer.result(False))
            self.active = False
        return heard

    def reset(self) -> None:
        """Forget the stretch in progress (the robot stopped moving, say)."""
        self.recognizer.reset()
        self.lead.clear()
        self.active = False
        self.quiet_samples = 0

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
