"""Live capture: espeak-ng Korean played into a PulseAudio null sink, heard through sounddevice and Vosk."""

from __future__ import annotations

import contextlib
import queue
import time

import pytest

from agent.speech import SpeechConfig, SpeechInput, SpeechUnavailable
from tests.speech.helpers import KOREAN, assert_heard, hear, running, wait_for


def test_wake_word_then_task_is_transcribed(mic, say, collector) -> None:
    config = SpeechConfig(**KOREAN)
    with running(config, collector) as speech:
        wait_for(lambda: speech.health()["state"] == "waiting_for_wake_word", 30, "the wake-word state")
        health = speech.health()
        assert health["ok"] and health["listening"] and health["audio_device"]["present"]
        assert health["model"]["runtime_grammar"] and health["grammar_bias"]
        assert health["vocabulary_size"] > 40

        said_at = time.time()
        transcript = hear(collector, lambda: mic.play(say("로봇 원점 이동")))
        assert_heard(transcript.text, "원점 이동")
        assert transcript.source == "wake_word"
        assert said_at - 1 <= transcript.started_at <= transcript.ended_at <= time.time()
        kinds = collector.kinds()
        assert kinds.index("ready") < kinds.index("wake") < kinds.index("listening") < kinds.index("heard")
        wait_for(lambda: speech.health()["state"] == "waiting_for_wake_word", 5, "the return to waiting")

        # Without the wake word nothing is taken as a task.
        mic.play(say("오른쪽 봐"))
        time.sleep(2.0)
        assert collector.transcripts.empty()
        assert speech.health()["transcripts"] == 1


def test_push_to_talk_takes_one_utterance(mic, say, collector) -> None:
    config = SpeechConfig(**{**KOREAN, "wake_words": ()})
    with running(config, collector) as speech:
        wait_for(lambda: speech.health()["state"] == "push_to_talk_only", 30, "push-to-talk readiness")
        mic.play(say("원점 이동"))
        time.sleep(1.0)
        assert collector.transcripts.empty(), "speech before push-to-talk must be ignored"

        def push_and_say() -> None:
            speech.listen_now()
            mic.play(say("오른쪽 봐"))

        transcript = hear(collector, push_and_say)
        assert_heard(transcript.text, "오른쪽 봐")
        assert transcript.source == "push_to_talk"


def test_push_to_talk_without_speech_times_out(mic, collector) -> None:
    config = SpeechConfig(**{**KOREAN, "wake_words": (), "no_speech_timeout_s": 1.0})
    with running(config, collector) as speech:
        wait_for(lambda: speech.health()["state"] == "push_to_talk_only", 30, "push-to-talk readiness")
        speech.listen_now()
        wait_for(lambda: "no_speech" in collector.kinds(), 5, "the no_speech event")
        assert collector.transcripts.empty()
        assert speech.health()["state"] == "push_to_talk_only"


def test_disabled_input_does_nothing(collector) -> None:
    speech = SpeechInput(SpeechConfig(enabled=False), collector.on_transcript, collector.on_event)
    speech.start()
    assert speech.health()["state"] == "disabled" and not speech.health()["ok"]
    with pytest.raises(SpeechUnavailable):
        speech.listen_now()
    speech.stop()


def test_lone_wake_word_then_task_and_a_failing_handler(mic, say) -> None:
    from agent.speech import SpeechEvent, Transcript

    texts: queue.Queue[str] = queue.Queue()
    calls: list[str] = []
    # What was played and what the input did, with times, for the failure messages.
    timeline: list[tuple[float, str]] = []
    began = time.time()

    def handler(transcript: Transcript) -> None:
        calls.append(transcript.text)
        texts.put(transcript.text)
        if len(calls) == 1:
            raise RuntimeError("a handler bug must not stop the speech input")

    def on_event(event: SpeechEvent) -> None:
        timeline.append((event.at, f"{event.kind} {event.detail}" if event.detail else event.kind))

    def play(text: str) -> None:
        timeline.append((time.time(), f"playing {text!r}"))
        mic.play(say(text))
        timeline.append((time.time(), f"played {text!r}"))

    def listenings() -> int:
        return sum(1 for _, what in list(timeline) if what.startswith("listening"))

    def history() -> str:
        return "; ".join(f"{at - began:.2f} s {what}" for at, what in sorted(timeline))

    speech = SpeechInput(SpeechConfig(**KOREAN), handler, on_event)
    speech.start()
    try:
        wait_for(lambda: speech.health()["state"] == "waiting_for_wake_word", 30, "the wake-word state")
        # "Robot." ... "back to the start": the task comes in the next utterance.
        # Synthetic speech gets a second try; each try must work end to end.
        heard = []
        for _ in range(2):
            before = listenings()
            play("로봇")
            with contextlib.suppress(AssertionError):
                wait_for(lambda before=before: listenings() >= before + 2 or not texts.empty(), 6,
                         "listening again for the task after a lone wake word")
            # Not retried: a lone wake word taken for a task would be a task nobody gave.
            assert texts.empty(), f"the lone wake word became the task {texts.get()!r}: {history()}"
            if listenings() >= before + 2:
                play("원점 이동")
                with contextlib.suppress(queue.Empty):
                    heard.append(texts.get(timeout=15))
                    if heard[-1].split()[:1] == ["원점"]:
                        break
            wait_for(lambda: speech.health()["state"] == "waiting_for_wake_word", 10, "the return to waiting")
        assert heard, f"no task after a lone wake word: {history()}"
        assert_heard(heard[-1], "원점 이동", history())

        wait_for(lambda: speech.health()["state"] == "waiting_for_wake_word", 5, "the return to waiting")
        transcripts = len(calls)
        for _ in range(2):
            play("로봇 원점 이동")
            with contextlib.suppress(queue.Empty):
                assert_heard(texts.get(timeout=15), "원점 이동", history())
                break
        assert len(calls) == transcripts + 1, f"the input stopped listening after the handler raised: {history()}"
    finally:
        speech.stop()


def test_a_stop_while_the_robot_moves_needs_no_wake_word_and_starts_nothing(mic, say, collector) -> None:
    # Issue 13: a spoken stop went through the wake word and the task recogniser, which heard "정지" as "전진".
    config = SpeechConfig(**KOREAN)
    with running(config, collector) as speech:
        wait_for(lambda: speech.health()["state"] == "waiting_for_wake_word", 30, "the wake-word state")
        speech.guard(True)
        mic.play(say("로봇 멈춰"))
        transcript = collector.transcripts.get(timeout=15)
        assert (transcript.text, transcript.source) == ("멈춰", "barge_in")
        time.sleep(2.0)  # the rest of that breath: no wake word, no task
        assert collector.transcripts.empty(), collector.transcripts.get()
        heard = [e for e in collector.events if e.kind == "stop_heard"]
        assert len(heard) == 1 and heard[0].detail["word"] == "멈춰"

        speech.guard(False)  # standing still: a bare stop word is not for the robot
        mic.play(say("멈춰"))
        time.sleep(2.0)
        assert collector.transcripts.empty(), \
            (collector.transcripts.get(), [(e.kind, e.detail) for e in collector.events])
