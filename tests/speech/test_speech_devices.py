"""Speech input without a working microphone: reported in health, retried, never raised."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from agent.speech import SpeechConfig, SpeechUnavailable
from tests.speech.helpers import KOREAN, assert_heard, hear, running, wait_for
from tests.speech.pulse import VirtualMic


def test_missing_device_is_reported_not_raised(audio_tools, collector) -> None:
    config = SpeechConfig(**{**KOREAN, "device": "nrtrans-no-such-mic", "retry_s": 0.2})
    with running(config, collector) as speech:
        wait_for(lambda: speech.health()["state"] == "no_device", 30, "the no_device state")
        health = speech.health()
        assert not health["ok"] and not health["listening"]
        assert health["model"]["loaded"], "the model loads even without a microphone"
        assert not health["audio_device"]["present"]
        assert "nrtrans-no-such-mic" in health["audio_device"]["error"]
        with pytest.raises(SpeechUnavailable, match="no_device"):
            speech.listen_now()
        time.sleep(0.6)
        assert collector.kinds().count("device_error") == 1, "a lasting problem is reported once"


def test_missing_model_is_reported_not_raised(tmp_path: Path, collector) -> None:
    config = SpeechConfig(model=str(tmp_path / "no-model"), language="ko")
    with running(config, collector) as speech:
        wait_for(lambda: speech.health()["state"] == "no_model", 10, "the no_model state")
        health = speech.health()
        assert not health["ok"] and not health["model"]["loaded"]
        assert "no Vosk model at" in health["model"]["error"]
        assert "model_error" in collector.kinds()
        with pytest.raises(SpeechUnavailable, match="no Vosk model"):
            speech.listen_now()


def test_microphone_that_appears_later_is_picked_up(audio_tools, say, collector) -> None:
    config = SpeechConfig(**{**KOREAN, "retry_s": 0.3})
    with running(config, collector) as speech:
        wait_for(lambda: speech.health()["model"]["loaded"], 30, "the model")
        with VirtualMic(rescan=False) as late:
            wait_for(lambda: speech.health()["state"] == "waiting_for_wake_word", 15,
                     "the speech input to find the new device")
            assert_heard(hear(collector, lambda: late.play(say("로봇 원점 이동"))).text, "원점 이동")
        wait_for(lambda: speech.health()["state"] == "no_device", 15, "the loss of the device")
        assert "device_lost" in collector.kinds() or "device_error" in collector.kinds()
