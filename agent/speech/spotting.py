"""Wake-word spotting with a small Vosk keyword grammar, and cutting the wake word off a transcript.

The spotter keeps the audio of the current stretch of speech, so a task said
in the same breath as the wake word ("robot, go back to the start") is
decoded in full by the task recogniser. Vosk's word timings say where the
wake word ended; the task transcript keeps only the words after that point,
which works even when the task recogniser hears the wake word as something
else.
"""

from __future__ import annotations

import json
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from agent.speech.audio import rms
from agent.speech.endpoint import MIN_SPEECH_RMS, NoiseFloor
from agent.speech.vocabulary import UNKNOWN, Vocabulary

# Slack when comparing word times from two recognisers of the same audio.
TIME_SLACK_S = 0.08
# Quiet audio kept before the first loud block of a task.
LEAD_IN_S = 0.5
# Quiet after which the wake recogniser stops listening to a stretch.
HANGOVER_S = 1.0
# Decodings of a stretch the wake spotter looks through for the wake word (see keyword_grammar and
# docs/speech.md: together they took the misses of the daemon voice test's phrase from 15 in 80 to none).
WAKE_ALTERNATIVES = 3


class TimedRecognizer:
    """A Vosk recogniser that knows how much audio it has had; Vosk's word times count from its creation."""

    def __init__(self, recognizer: Any, rate: int) -> None:
        self.recognizer = recognizer
        self.rate = rate
        self.fed = 0
        # Word times in final results only: with partial words on, Vosk holds
        # partial results back for seconds, which would delay wake-up.
        recognizer.SetWords(True)

    def accept(self, block: bytes) -> bool:
        self.fed += len(block) // 2
        return bool(self.recognizer.AcceptWaveform(block))

    @property
    def now(self) -> float:
        return self.fed / self.rate

    def result(self, endpoint: bool) -> dict[str, Any]:
        raw = self.recognizer.Result() if endpoint else self.recognizer.FinalResult()
        parsed: dict[str, Any] = json.loads(raw)
        return parsed

    def partial(self) -> dict[str, Any]:
        parsed: dict[str, Any] = json.loads(self.recognizer.PartialResult())
        return parsed

    def reset(self) -> None:
        self.recognizer.Reset()


@dataclass(frozen=True)
class WakeHit:
    audio: tuple[bytes, ...]
    # Where the wake word ends, in seconds from the start of `audio`.
    wake_end_s: float


class SpeechGate:
    """Lets audio through to a recogniser only around loud stretches.

    Hours of silence fed to Vosk drift its speaker adaptation until it stops
    hearing the words it spots (and cost CPU); so quiet audio only fills a
    short lead-in, handed over when speech starts, and a stretch of speech
    ends after a hangover of quiet.
    """

    def __init__(self, rate: int, hangover_s: float) -> None:
        self.rate = rate
        self.noise = NoiseFloor()
        self.lead: deque[bytes] = deque()
        self.hangover_samples = int(hangover_s * rate)
        self.active = False
        self.quiet_samples = 0

    def admit(self, block: bytes) -> list[bytes]:
        """The blocks to decode now: none while quiet, the lead-in and `block` when speech starts, else `block`."""
        loud = self.noise.is_loud(block)
        if not self.active:
            if not loud:
                self.lead.append(block)
                while sum(len(b) for b in self.lead) // 2 > LEAD_IN_S * self.rate:
                    self.lead.popleft()
                return []
            self.active = True
            self.quiet_samples = 0
            blocks, self.lead = [*self.lead, block], deque()
            return blocks
        self.quiet_samples = 0 if loud else self.quiet_samples + len(block) // 2
        return [block]

    @property
    def ended(self) -> bool:
        """A stretch of speech was going on and has been quiet for the whole hangover."""
        return self.active and self.quiet_samples >= self.hangover_samples

    def close(self) -> None:
        self.active = False
        self.quiet_samples = 0

    def reset(self) -> None:
        self.lead.clear()
        self.close()


class WakeSpotter:
    """Feeds the keyword recogniser only around loud audio.

    Hours of silence fed to Vosk drift its speaker adaptation until it stops
    hearing the wake word (and cost CPU); gating by loudness keeps the
    recogniser on speech, with a lead-in before and a hangover after.
    """

    def __init__(self, recognizer: TimedRecognizer, wake_words: Sequence[str], preroll_s: float,
                 hangover_s: float = HANGOVER_S) -> None:
        self.recognizer = recognizer
        recognizer.recognizer.SetMaxAlternatives(WAKE_ALTERNATIVES)
        self.phrases = [tuple(w.lower().split()) for w in wake_words if w.split()]
        self.gate = SpeechGate(recognizer.rate, hangover_s)
        self.audio: deque[bytes] = deque()
        self.audio_samples = 0
        self.max_samples = int(preroll_s * recognizer.rate)

    def feed(self, block: bytes) -> WakeHit | None:
        for piece in self.gate.admit(block):
            hit = self._accept(piece)
            if hit is not None:
                return self._close(hit)
        if self.gate.ended:
            return self._close(self._judge(self.recognizer.result(False)))
        return None

    def reset(self) -> None:
        """Forget the stretch in progress: it was a stop, not the start of a task."""
        self.recognizer.reset()
        self.gate.reset()
        self.audio.clear()
        self.audio_samples = 0

    def _accept(self, block: bytes) -> WakeHit | None:
        self.audio.append(block)
        self.audio_samples += len(block) // 2
        while self.audio_samples > self.max_samples and len(self.audio) > 1:
            self.audio_samples -= len(self.audio.popleft()) // 2
        if self.recognizer.accept(block):
            return self._judge(self.recognizer.result(True))
        if not self._mentions_wake_word(str(self.recognizer.partial().get("partial", ""))):
            return None
        # Closing the utterance now gives the word times of the wake word. A partial result flickers,
        # so the decodings of the closed stretch decide: trusting the partial alone woke the robot for
        # a bare "멈춰" and for sentences without the wake word (docs/speech.md, bench_wake_spotter.py).
        return self._judge(self.recognizer.result(False))

    def _judge(self, result: dict[str, Any]) -> WakeHit | None:
        """A hit when the closed stretch of speech holds the wake word; the stretch is forgotten either way."""
        decodings = [a.get("result") or [] for a in result.get("alternatives") or []] or [result.get("result") or []]
        end = next((e for e in (phrase_end(words, self.phrases) for words in decodings) if e is not None), None)
        audio, samples = tuple(self.audio), self.audio_samples
        # Forget the stretch, so an earlier sentence is not glued onto the next task.
        self.audio.clear()
        self.audio_samples = 0
        if end is None:
            return None
        audio_start = self.recognizer.now - samples / self.recognizer.rate
        return WakeHit(audio, max(0.0, end - audio_start))

    def _close(self, hit: WakeHit | None) -> WakeHit | None:
        if hit is not None or self.gate.ended:
            self.gate.close()
        return hit

    def _mentions_wake_word(self, text: str) -> bool:
        padded = f" {text.lower()} "
        return any(f" {' '.join(phrase)} " in padded for phrase in self.phrases)


def keyword_grammar(keywords: Sequence[str], vocabulary: Vocabulary, *, long_decoys_only: bool = False) -> str:
    """A spotter's phrase list: the keywords, and somewhere for other speech to go.

    Without [unk] a closed grammar would hear a keyword in every sound, so a
    model without it gets the other task words as decoys; with
    `long_decoys_only`, only those at least as long as the shortest keyword,
    since a shorter one (the Korean number word "오" against "로봇") can
    swallow the keyword itself.
    """
    words = list(dict.fromkeys(k.lower() for k in keywords))
    shortest = min((len(w) for w in words), default=0) if long_decoys_only else 0
    others = [UNKNOWN] if vocabulary.has_unknown else [w for w in vocabulary.words
                                                         if w not in words and len(w) >= shortest]
    return json.dumps([*words, *others], ensure_ascii=False)


def trim_leading_quiet(audio: tuple[bytes, ...], rate: int,
                       keep_s: float = LEAD_IN_S) -> tuple[tuple[bytes, ...], float]:
    """Drop quiet blocks before the speech, keeping `keep_s` of lead-in; returns (audio, seconds dropped).

    Vosk adapts to the audio it has heard, so a task decoded after six
    seconds of silence comes out differently from the same task after half
    a second. A fixed lead-in makes live decoding match file decoding.
    """
    first_loud = next((i for i, block in enumerate(audio) if rms(block) > MIN_SPEECH_RMS), len(audio))
    start = 0
    kept_before = 0.0
    for index in range(first_loud - 1, -1, -1):
        kept_before += len(audio[index]) / 2 / rate
        if kept_before > keep_s:
            start = index + 1
            break
    dropped_samples = sum(len(block) // 2 for block in audio[:start])
    return audio[start:], dropped_samples / rate


def phrase_end(words: list[dict[str, Any]], phrases: Sequence[tuple[str, ...]]) -> float | None:
    """End time of the first wake phrase in Vosk's word list, or None."""
    spoken = [str(w.get("word", "")).lower() for w in words]
    for index in range(len(spoken)):
        for phrase in phrases:
            if tuple(spoken[index:index + len(phrase)]) == phrase:
                return float(words[index + len(phrase) - 1].get("end", 0.0))
    return None


def _after_cut(word: dict[str, Any], cut_s: float) -> bool:
    """Whether a word of the task recogniser was said after the wake word that ended at `cut_s`.

    By the middle of the word: a task recogniser that hears the tail of the
    wake word as a short word places it before the cut. And by its end: a word
    that ends with the wake word is the wake word heard as something else (a
    lone "로봇" heard as the number word "오" at 0.72-0.87 s, cut at 0.87 s),
    which the middle alone let through at some block alignments.
    """
    start, end = float(word.get("start", 0.0)), float(word.get("end", 0.0))
    return (start + end) / 2 >= cut_s - TIME_SLACK_S and end > cut_s + TIME_SLACK_S


def words_after(result: dict[str, Any], cut_s: float | None, wake_words: Sequence[str]) -> str:
    """The transcript of `result` after time `cut_s`, without a leading wake word or noise markers."""
    words = result.get("result")
    if words and cut_s is not None:
        kept = [str(w["word"]) for w in words if _after_cut(w, cut_s)]
    elif words:
        kept = [str(w["word"]) for w in words]
    else:
        kept = str(result.get("text", "")).split()
    kept = [w for w in kept if not (w.startswith("[") and w.endswith("]"))]
    phrases = [tuple(w.lower().split()) for w in wake_words if w.split()]
    # A wake word the task recogniser heard at the very start is not part of the task.
    for index in range(min(3, len(kept))):
        for phrase in phrases:
            if tuple(x.lower() for x in kept[index:index + len(phrase)]) == phrase:
                return " ".join(kept[index + len(phrase):])
    return " ".join(kept)
