"""Live speech input: microphone -> wake word or push-to-talk -> Vosk -> transcript.

One worker thread owns the audio stream and the recognisers, so Vosk is never
used from two threads. PortAudio's callback only queues raw blocks. While the
robot moves (`guard(True)`), a stop-only listener (agent.speech.stop) hears
every loud block as well, without the wake word: its only possible output is
a stop, handed on as a `barge_in` transcript of the stop word, and it drops
any task utterance in progress, so a stop misheard by the task recogniser
cannot become a motion. Nothing here may take the daemon down: a missing
model or microphone, a device that disappears, or a callback that raises is
logged, reported in `health()` and retried, while the rest of the daemon
keeps serving.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from agent.speech.endpoint import SilenceDetector
from agent.speech.feedback import Speaker, describe
from agent.speech.lexicon import lexicon_for
from agent.speech.recognizer import LoadedModel, load_model
from agent.speech.records import SpeechConfig, SpeechEvent, Transcript, TranscriptSource
from agent.speech.spotting import TimedRecognizer, WakeSpotter, keyword_grammar, trim_leading_quiet, words_after
from agent.speech.stop import StopHeard, StopSpotter, stop_grammar
from agent.speech.vocabulary import Vocabulary
from rsl.plan import Command

log = logging.getLogger("nrtrans.speech")

# Audio kept before a wake word is confirmed, so the task said in the same
# breath ("robot, go forward") is not lost.
PREROLL_S = 6.0
# No block for this long from a running stream means the device is gone.
STALL_S = 3.0
QUEUE_BLOCKS = 300


class SpeechUnavailable(RuntimeError):
    """Push-to-talk asked for while the speech input cannot listen; says why."""


@dataclass
class _Utterance:
    source: TranscriptSource
    started_at: float
    detector: SilenceDetector
    # The task recogniser's time where the wake word ended; words before it
    # are not part of the task.
    cut_s: float | None
    # After a lone wake word the task comes in a second utterance.
    follow_up: bool = False


class SpeechInput:
    def __init__(self, config: SpeechConfig, on_transcript: Callable[[Transcript], None],
                 on_event: Callable[[SpeechEvent], None] | None = None) -> None:
        self.config = config
        self._on_transcript = on_transcript
        self._on_event = on_event
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._push_to_talk = threading.Event()
        self._objects_changed = threading.Event()
        self._guarding = threading.Event()
        self._objects: tuple[str, ...] = tuple(config.objects)
        self._thread: threading.Thread | None = None
        self._blocks: queue.Queue[bytes] = queue.Queue(maxsize=QUEUE_BLOCKS)
        self._state = "stopped" if config.enabled else "disabled"
        self._model_info: dict[str, Any] = {"loaded": False, "path": None, "runtime_grammar": False,
                                            "error": None}
        self._device_info: dict[str, Any] = {"present": False, "name": None, "sample_rate": None,
                                             "error": None}
        self._vocabulary_size = 0
        self._dropped = 0
        self._transcripts = 0
        self._model: LoadedModel | None = None
        self._wake_words = tuple(w.lower() for w in config.wake_words)
        self._speaker = Speaker(config.feedback_voice, enabled=config.feedback)

    # -- the public interface -------------------------------------------------------------

    def start(self) -> None:
        """Start listening in the background; never raises for a missing model or microphone."""
        if not self.config.enabled or self._thread is not None:
            return
        self._stopping.clear()
        self._set_state("starting")
        self._thread = threading.Thread(target=self._run, name="nrtrans-speech", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        self._stopping.set()
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.join(timeout)
        self._speaker.close()
        if self.config.enabled:
            self._set_state("stopped")

    def listen_now(self) -> None:
        """Push-to-talk: take the next utterance without a wake word."""
        with self._lock:
            state = self._state
            problem = self._model_info["error"] or self._device_info["error"]
        if state not in ("waiting_for_wake_word", "push_to_talk_only", "listening"):
            raise SpeechUnavailable(f"speech input cannot listen now ({state}"
                                    f"{': ' + problem if problem else ''}); see `nrtrans health`")
        self._push_to_talk.set()

    def guard(self, moving: bool) -> None:
        """Tell the speech input whether the robot is moving: the stop listener runs only then."""
        if moving:
            self._guarding.set()
        else:
            self._guarding.clear()

    def announce(self, command: Command) -> bool:
        """Say a plan step aloud when `feedback` is on; never blocks, never raises."""
        try:
            return self._speaker.speak(describe(command))
        except Exception:
            log.exception("spoken feedback failed for %s", command.skill)
            return False

    def say(self, text: str, *, wait_s: float = 0.0) -> bool:
        """Say `text` when `feedback` is on (explain-back, a question), waiting up to `wait_s` for it to end."""
        try:
            return self._speaker.speak(text, wait_s=wait_s)
        except Exception:
            log.exception("spoken feedback failed for %r", text)
            return False

    def set_objects(self, names: tuple[str, ...] | list[str]) -> None:
        """Bias toward these object names from the next utterance on (e.g. after `perceive`)."""
        with self._lock:
            self._objects = tuple(dict.fromkeys([*self.config.objects, *names]))
        self._objects_changed.set()

    def health(self) -> dict[str, Any]:
        with self._lock:
            listening = self._state in ("waiting_for_wake_word", "push_to_talk_only", "listening")
            return {
                "ok": self.config.enabled and listening,
                "enabled": self.config.enabled,
                "state": self._state,
                "listening": listening,
                "model": dict(self._model_info),
                "audio_device": dict(self._device_info),
                "grammar_bias": self.config.grammar_bias and bool(self._model_info["runtime_grammar"]),
                "vocabulary_size": self._vocabulary_size,
                "wake_words": list(self._wake_words),
                "dropped_blocks": self._dropped,
                "transcripts": self._transcripts,
                "feedback": {"on": self._speaker.enabled, "reason": self._speaker.reason},
            }

    # -- the worker -----------------------------------------------------------------------

    def _run(self) -> None:
        try:
            self._model = self._load()
        except Exception as exc:
            message = str(exc)
            with self._lock:
                self._model_info.update(loaded=False, error=message)
            self._set_state("no_model")
            self._emit("model_error", reason=message)
            log.warning("speech input has no model: %s", message)
            self._probe_device()
            return
        reported = ""
        while not self._stopping.is_set():
            try:
                stream, rate = self._open_stream()
            except Exception as exc:
                message = str(exc) or type(exc).__name__
                with self._lock:
                    self._device_info.update(present=False, error=message)
                self._set_state("no_device")
                if message != reported:
                    reported = message
                    self._emit("device_error", reason=message)
                    log.warning("speech input has no audio device: %s; retrying every %.0f s",
                                message, self.config.retry_s)
                self._stopping.wait(self.config.retry_s)
                _rescan_devices()
                continue
            reported = ""
            try:
                self._listen(stream, rate)
            except _DeviceLost as exc:
                with self._lock:
                    self._device_info.update(present=False, error=str(exc))
                self._set_state("no_device")
                self._emit("device_lost", reason=str(exc))
                log.warning("audio device lost: %s", exc)
            except Exception as exc:
                log.exception("speech input failed; restarting it")
                self._emit("device_error", reason=f"{type(exc).__name__}: {exc}")
                self._stopping.wait(self.config.retry_s)
            finally:
                _close(stream)
        self._emit("stopped")

    def _load(self) -> LoadedModel:
        from models.store import resolve_vosk

        lexicon_for(self.config.language)
        path = resolve_vosk(self.config.model)
        with self._lock:
            self._model_info.update(path=str(path))
        model = load_model(path)
        with self._lock:
            self._model_info.update(loaded=True, runtime_grammar=model.runtime_grammar, error=None)
        return model

    def _vocabulary(self, model: LoadedModel) -> Vocabulary:
        from rsl.profile import load_profile

        with self._lock:
            objects = self._objects
        vocabulary = model.vocabulary(load_profile(self.config.profile), self.config.language, objects,
                                      self._wake_words)
        with self._lock:
            self._vocabulary_size = len(vocabulary)
        return vocabulary

    def _probe_device(self) -> None:
        """Fill in the device half of `health` even when there is no model to listen with."""
        try:
            import sounddevice as sd

            info = sd.query_devices(self.config.device, "input")
            with self._lock:
                self._device_info.update(present=True, name=info["name"], error=None)
        except Exception as exc:
            with self._lock:
                self._device_info.update(present=False, error=_device_message(exc, self.config.device))

    def _open_stream(self) -> tuple[Any, int]:
        try:
            import sounddevice as sd
        except OSError as exc:
            raise RuntimeError(f"PortAudio is not installed ({exc}); install libportaudio2") from None
        device = self.config.device
        try:
            info = sd.query_devices(device, "input")
        except Exception as exc:
            raise RuntimeError(_device_message(exc, device)) from None
        rate = self.config.sample_rate
        try:
            sd.check_input_settings(device=device, samplerate=rate, channels=1, dtype="int16")
        except Exception:
            # Vosk takes any rate, so use what the device offers rather than fail.
            rate = int(info["default_samplerate"])
        self._blocks = queue.Queue(maxsize=QUEUE_BLOCKS)
        blocks = self._blocks

        def on_audio(data: Any, frames: int, when: Any, status: Any) -> None:
            try:
                blocks.put_nowait(bytes(data))
            except queue.Full:
                with self._lock:
                    self._dropped += 1

        stream = sd.RawInputStream(device=device, samplerate=rate, channels=1, dtype="int16",
                                   blocksize=rate // 10, callback=on_audio)
        try:
            stream.start()
        except Exception:
            _close(stream)
            raise
        with self._lock:
            self._device_info.update(present=True, name=info["name"], sample_rate=rate, error=None)
        return stream, rate

    def _listen(self, stream: Any, rate: int) -> None:
        assert self._model is not None
        model = self._model
        vocabulary = self._vocabulary(model)
        bias = self.config.grammar_bias and model.runtime_grammar
        task = TimedRecognizer(model.recognizer(rate, vocabulary.grammar() if bias else None), rate)
        spotter = None
        if self._wake_words:
            grammar = keyword_grammar(self._wake_words, vocabulary, long_decoys_only=True)
            wake = TimedRecognizer(model.recognizer(rate, grammar), rate)
            spotter = WakeSpotter(wake, self._wake_words, PREROLL_S)
        stop_words = [w for w in lexicon_for(self.config.language).stop_words if model.find_word(w) >= 0]
        stop = StopSpotter(TimedRecognizer(model.recognizer(rate, stop_grammar(stop_words, vocabulary)), rate),
                           stop_words, self.config.stop_threshold) \
            if self.config.barge_in and stop_words and model.runtime_grammar else None
        holdoff = False  # after a barge-in, until that stretch of speech ends
        utterance: _Utterance | None = None
        idle_state = "waiting_for_wake_word" if spotter is not None else "push_to_talk_only"
        self._set_state(idle_state)
        self._emit("ready", device=self._device_info["name"], sample_rate=rate,
                   vocabulary_size=len(vocabulary) if bias else 0)
        last_block = time.monotonic()
        while not self._stopping.is_set():
            try:
                block = self._blocks.get(timeout=0.5)
            except queue.Empty:
                if time.monotonic() - last_block > STALL_S or not stream.active:
                    raise _DeviceLost("the audio device stopped delivering sound") from None
                continue
            last_block = time.monotonic()
            if stop is not None and (self._guarding.is_set() or holdoff):
                heard = stop.feed(block)
                if heard is not None and self._guarding.is_set() and not holdoff:
                    self._barge_in(heard, task, utterance)
                    utterance = None
                    if spotter is not None:
                        spotter.reset()
                    self._set_state(idle_state)
                    # The rest of this breath is not for the wake word either: "정지" heard as "로봇 전진"
                    # must not start a task once the robot has stopped.
                    holdoff = True
                if holdoff:
                    holdoff = stop.active
                    continue
            elif stop is not None and stop.active:
                stop.reset()
            if utterance is None and self._objects_changed.is_set():
                self._objects_changed.clear()
                vocabulary = self._vocabulary(model)
                task = TimedRecognizer(model.recognizer(rate, vocabulary.grammar() if bias else None), rate)
            if utterance is None and self._push_to_talk.is_set():
                self._push_to_talk.clear()
                utterance = self._begin(task, "push_to_talk", ())
            if utterance is None:
                hit = spotter.feed(block) if spotter is not None else None
                if hit is not None:
                    self._emit("wake")
                    utterance = self._begin(task, "wake_word", hit.audio, hit.wake_end_s)
                continue
            utterance = self._continue(utterance, task, block)
            if utterance is None:
                self._set_state(idle_state)

    def _barge_in(self, heard: StopHeard, task: TimedRecognizer, utterance: _Utterance | None) -> None:
        """A stop heard while the robot moves: drop the utterance in progress and hand on only the stop."""
        if utterance is not None:
            task.reset()
        now = time.time()
        try:
            self._on_transcript(Transcript(heard.word, now, now, "barge_in"))
        except Exception:
            log.exception("the transcript handler failed for the stop word %r", heard.word)
        self._emit("stop_heard", word=heard.word, confidence=round(heard.confidence, 3),
                   dropped_utterance=utterance is not None)

    def _begin(self, task: TimedRecognizer, source: TranscriptSource, audio: tuple[bytes, ...],
               wake_end_s: float | None = None, follow_up: bool = False) -> _Utterance:
        task.reset()
        detector = SilenceDetector(task.rate, self.config.silence_ms)
        audio, dropped = trim_leading_quiet(audio, task.rate)
        seconds = sum(len(b) for b in audio) / 2 / task.rate
        cut = None if wake_end_s is None else task.now + wake_end_s - dropped
        utterance = _Utterance(source, time.time() - seconds, detector, cut, follow_up)
        for block in audio:
            task.accept(block)
            detector.feed(block)
        self._set_state("listening")
        self._emit("listening", source=source)
        return utterance

    def _continue(self, utterance: _Utterance, task: TimedRecognizer, block: bytes) -> _Utterance | None:
        """Feed one block; returns the utterance still in progress, or None when it is over."""
        endpoint = task.accept(block)
        silent = utterance.detector.feed(block)
        detector = utterance.detector
        if not detector.heard_speech and detector.seconds >= self.config.no_speech_timeout_s:
            task.reset()
            self._emit("no_speech", source=utterance.source)
            return None
        if endpoint and not detector.heard_speech:
            # Vosk closes a segment on its own silence rules; before any speech
            # that is just the room, so keep waiting.
            return utterance
        if not (endpoint or silent or detector.seconds >= self.config.max_utterance_s):
            return utterance
        text = words_after(task.result(endpoint), utterance.cut_s, self._wake_words)
        task.reset()
        if not text:
            if utterance.source == "wake_word" and not utterance.follow_up:
                # "Robot." ... "go forward": the task comes next.
                return self._begin(task, "wake_word", (), follow_up=True)
            self._emit("empty", source=utterance.source)
            return None
        transcript = Transcript(text, utterance.started_at, time.time(), utterance.source)
        with self._lock:
            self._transcripts += 1
        self._emit("heard", text=text, source=utterance.source)
        try:
            self._on_transcript(transcript)
        except Exception:
            log.exception("the transcript handler failed for %r", text)
        return None

    # -- reporting ------------------------------------------------------------------------

    def _set_state(self, state: str) -> None:
        with self._lock:
            self._state = state

    def _emit(self, kind: str, **detail: Any) -> None:
        if self._on_event is None:
            return
        try:
            self._on_event(SpeechEvent(kind, time.time(), detail))
        except Exception:
            log.exception("the speech event handler failed for %s", kind)


class _DeviceLost(RuntimeError):
    pass


def _rescan_devices() -> None:
    """Restart PortAudio so a microphone plugged in (or a sound server started) since is seen."""
    try:
        import sounddevice as sd

        sd._terminate()
        sd._initialize()
    except Exception as exc:
        log.debug("rescanning audio devices: %s", exc)


def _close(stream: Any) -> None:
    try:
        stream.stop()
    except Exception as exc:
        log.debug("stopping the audio stream: %s", exc)
    try:
        stream.close()
    except Exception as exc:
        log.debug("closing the audio stream: %s", exc)


def _device_message(exc: BaseException, device: str | int | None) -> str:
    which = "the default input device" if device is None else f"input device {device!r}"
    return (f"{which} is not available ({exc}). Plug in a microphone or set speech.device "
            "(list them with `python -m sounddevice`).")
