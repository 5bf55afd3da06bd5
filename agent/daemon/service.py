"""The service: loads the profile, translator and robot, and runs tasks one at a time.

Requests arrive from the socket server's event loop and only ever queue,
cancel or inspect; the worker thread is the one place a program reaches the
robot, and it does so only with a plan the compiler verified. Every change
of a task goes to the audit log (fsync'd) before it is announced.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import os
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from agent.daemon.audit import AuditError, AuditLog
from agent.daemon.config import Config, TranslatorConfig
from agent.daemon.confirm import Question
from agent.daemon.events import EventBus
from agent.daemon.health import describe
from agent.daemon.protocol import ProtocolError
from agent.daemon.tasks import Busy, Peer, Task, TaskQueue, TaskState
from agent.daemon.voice import Speech
from agent.executor import ExecutionResult, StepEvent
from agent.pipeline import Attempted, Cancelled, Draft, Pipeline, Rejected, TaskTranslator, Verified
from agent.robot import Robot, Status
from agent.translate.confidence import UNSURE_BELOW
from rsl.profile import Profile

if TYPE_CHECKING:
    from agent.record import Recorder
    from agent.speech import SpeechEvent, Transcript

log = logging.getLogger(__name__)


# The longest the robot waits for its plan to be said before it moves (only with spoken feedback on).
_EXPLAIN_WAIT_S = 8.0


class StartupError(RuntimeError):
    """A part the daemon cannot run without failed to load; the message says what to do."""


class Service:
    def __init__(self, config: Config, *, on_status: Callable[[str], None] = lambda _s: None) -> None:
        self.config = config
        self.events = EventBus()
        self.queue = TaskQueue(config.tasks.queue_size)
        self.audit = AuditLog(config.audit_path(), max_bytes=config.audit.max_bytes, keep=config.audit.keep)
        self.on_status = on_status
        self.profile: Profile | None = None
        self.translator: TaskTranslator | None = None
        self.robot: Robot | None = None
        # Set once all three above are loaded: the path a task takes (agent/pipeline.py).
        self.pipeline: Pipeline | None = None
        self.speech: Speech | None = None
        self.speech_problem = "not started"
        self.started = time.monotonic()
        self._lock = threading.Lock()
        self._tasks: OrderedDict[str, Task] = OrderedDict()
        self._current: Task | None = None
        self._estop_reason: str | None = None
        self._stopping = False
        self._worker: threading.Thread | None = None
        self._worker_error: str | None = None
        self.warm_s: float | None = None
        self._questions: dict[str, Question] = {}

    # -- start and stop -------------------------------------------------------------------------

    def load(self) -> None:
        """Load everything a task needs; raises `StartupError` with the reason and a fix."""
        self.on_status("opening the audit log")
        try:
            for record in self.audit.open():
                log.warning(
                    "task %s was in flight when the daemon last stopped; marked interrupted and not run again",
                    record["task"],
                )
        except AuditError as exc:
            raise StartupError(str(exc.strerror)) from exc
        self.on_status("loading the robot profile")
        self.profile = _load_profile(self.config.robot.profile)
        self.on_status("loading the translation model")
        self.translator = _load_translator(self.config, self.profile)
        self.on_status(f"opening the {self.config.robot.backend} backend")
        self.robot = _open_robot(self.config, self.profile)
        self.pipeline = Pipeline(self.profile, self.translator, self.robot)
        if self.config.speech.enabled:
            self.on_status("starting speech input")
            self._start_speech()
        else:
            self.speech_problem = "disabled in the config ([speech] enabled = false)"
        self._worker = threading.Thread(target=self._work, name="nrtrans-worker", daemon=True)
        self._worker.start()

    def shutdown(self, reason: str = "the daemon is shutting down") -> None:
        """Stop the robot first, then let the task in progress end and record it."""
        with self._lock:
            self._stopping = True
            current = self._current
        if current is not None:
            current.cancel.set(reason)
        self._stop_robot()
        self.queue.close()
        for task in self.queue.drain():
            self._finish(task, TaskState.CANCELLED, reason)
        if self._worker is not None:
            # Only a task in progress is worth waiting for; a warm-up translation is not.
            self._worker.join(self.config.tasks.shutdown_grace if current is not None else 1.0)
            if self._worker.is_alive() and current is not None:
                # Still inside a translation that cannot be interrupted; nothing has moved.
                self._finish(current, TaskState.CANCELLED, reason)
        if self.speech is not None:
            _quietly(self.speech.stop)
        if self.robot is not None:
            _quietly(self.robot.close)
        if self.translator is not None and not self.worker_busy():
            # A translation still running holds the model; the process exits without waiting for it.
            _quietly(self.translator.close)
        self.audit.close()

    def worker_busy(self) -> bool:
        return self._worker is not None and self._worker.is_alive()

    def alive(self) -> bool:
        return self._worker is not None and self._worker.is_alive() and self._worker_error is None

    def apply_config(self, new: Config) -> list[str]:
        """Take over the settings that can change while running; returns those that cannot."""
        needs_restart = [
            name
            for name, old, changed in (
                ("state_dir", self.config.state_path(), new.state_path()),
                ("api.socket", self.config.socket_path(), new.socket_path()),
                ("translator", _needs_restart(self.config.translator), _needs_restart(new.translator)),
                ("robot", self.config.robot, new.robot),
                ("speech", self.config.speech, new.speech),
                ("audit.file", self.config.audit.file, new.audit.file),
            )
            if old != changed
        ]
        self.queue.capacity = new.tasks.queue_size
        self.audit.max_bytes = new.audit.max_bytes
        self.audit.keep = new.audit.keep
        self.config = new
        return needs_restart

    # -- requests ---------------------------------------------------------------------------

    def submit(
        self,
        *,
        source: str,
        text: str | None = None,
        rsl: str | None = None,
        peer: Peer | None = None,
        before_queue: Callable[[Task], None] | None = None,
    ) -> tuple[Task, int]:
        task = Task(source=source, text=text, rsl=rsl, peer=peer)
        with self._lock:
            if self._stopping:
                raise ProtocolError(
                    "shutting_down", "the daemon is shutting down", "submit again once it has restarted"
                )
            if self._estop_reason is not None:
                raise ProtocolError(
                    "estopped",
                    f"an emergency stop is latched ({self._estop_reason})",
                    "check that the robot is safe, then send `reset` (`nrtrans reset`)",
                )

            def accept(position: int) -> None:
                if before_queue is not None:
                    before_queue(task)
                # On disk before the reply, so an accepted task is never missing from the log.
                self.audit.write(task.record())
                self.events.publish("queued", task.id, source=source, position=position, text=text, rsl=rsl)

            try:
                position = self.queue.put(task, accept)
            except Busy as exc:
                raise ProtocolError(
                    "busy",
                    f"the task queue is full: {exc}",
                    "wait for a task to finish (`nrtrans events`) and submit again",
                ) from exc
            self._remember(task)
        return task, position

    def task(self, task_id: str) -> Task:
        with self._lock:
            task = self._tasks.get(task_id)
        if task is None:
            raise ProtocolError(
                "not_found",
                f"no task {task_id!r} is known to this daemon",
                "`nrtrans history` lists the recent tasks, including ones before a restart",
            )
        return task

    def cancel(self, task_id: str) -> Task:
        task = self.task(task_id)
        if self.queue.remove(task_id) is not None:
            self._finish(task, TaskState.CANCELLED, "cancelled by request before it started")
        elif not task.state.finished:
            task.cancel.set("cancelled by request")
        return task

    def estop(self, reason: str) -> None:
        """Stop the robot before anything else, then latch and cancel all work."""
        self._stop_robot()
        with self._lock:
            self._estop_reason = reason
        self._cancel_all(f"emergency stop: {reason}")
        self.events.publish("estop", None, reason=reason)
        self.on_status(f"EMERGENCY STOP latched: {reason}; send reset to resume")

    def halt(self, reason: str) -> list[str]:
        """Stop the robot and cancel the running and queued tasks, latching nothing; returns their ids."""
        self._stop_robot()
        return self._cancel_all(reason)

    def _cancel_all(self, reason: str) -> list[str]:
        with self._lock:
            current = self._current
        cancelled = []
        if current is not None and not current.state.finished:
            current.cancel.set(reason)
            cancelled.append(current.id)
        for task in self.queue.drain():
            self._finish(task, TaskState.CANCELLED, reason)
            cancelled.append(task.id)
        return cancelled

    def reset(self) -> bool:
        with self._lock:
            was_latched = self._estop_reason is not None
            self._estop_reason = None
        if was_latched:
            log.info("emergency stop released")
            self.events.publish("reset", None)
            self.on_status(self.idle_status())
        return was_latched

    def daemon_status(self) -> dict[str, Any]:
        with self._lock:
            current = self._current
            estop = self._estop_reason
        state = "estopped" if estop is not None else "busy" if current is not None else "idle"
        return {
            "state": state,
            "estop": estop,
            "current": current.id if current else None,
            "queued": len(self.queue),
            "queue_size": self.queue.capacity,
            "backend": self.config.robot.backend,
            "pid": os.getpid(),
            "uptime_s": round(time.monotonic() - self.started, 3),
        }

    def health(self) -> tuple[bool, dict[str, Any]]:
        robot: dict[str, Any] = {"ok": False, "backend": self.config.robot.backend}
        if self.robot is None:
            robot["detail"] = "the backend is not open"
        else:
            try:
                robot.update(ok=True, state=self.robot.state().to_dict())
            except Exception as exc:
                robot["detail"] = f"cannot read the robot state: {exc}"
        speech: dict[str, Any] = {"ok": self.speech is not None}
        if self.speech is not None:
            try:
                speech.update(self.speech.health())
            except Exception as exc:
                speech.update(ok=False, detail=f"speech health check failed: {exc}")
        else:
            speech["detail"] = self.speech_problem
        components: dict[str, dict[str, Any]] = {
            "worker": {"ok": self.alive(), **({"detail": self._worker_error} if self._worker_error else {})},
            "translator": {
                "ok": self.translator is not None,
                "warm_s": self.warm_s,
                "model": (self.translator.model_name if self.translator is not None else "")
                or self.config.translator.model or "embedded",
            },
            "robot": robot,
            "audit": {"ok": self.audit._file is not None, "path": str(self.audit.path)},
            "speech": speech,
            "estop": {
                "ok": self._estop_reason is None,
                "latched": self._estop_reason is not None,
                "reason": self._estop_reason,
            },
        }
        describe(components, backend=self.config.robot.backend, speech_problem=self.speech_problem)
        # Speech is optional: the daemon is healthy without a microphone.
        healthy = all(components[k]["ok"] for k in ("worker", "translator", "robot", "audit"))
        return healthy, components

    def listen(self) -> None:
        if self.speech is None:
            raise ProtocolError(
                "unavailable",
                f"speech input is not running: {self.speech_problem}",
                "see `nrtrans health`; submit text with `nrtrans send` meanwhile",
            )
        try:
            self.speech.listen_now()
        except RuntimeError as exc:
            raise ProtocolError("unavailable", str(exc), "see `nrtrans health` for the audio device and model") from exc

    def idle_status(self) -> str:
        return f"ready: {self.config.robot.backend} backend, listening on {self.config.socket_path()}"

    # -- the worker ---------------------------------------------------------------------------

    def _work(self) -> None:
        if self.config.translator.warmup:
            self._warm_up()
        while True:
            task = self.queue.get()
            if task is None:
                return
            with self._lock:
                self._current = task
            try:
                self._run(task)
            except AuditError as exc:
                # Without an audit trail nothing may move: stop and report unhealthy.
                self._stop_robot()
                self._worker_error = str(exc.strerror)
                log.error("audit log failed; the worker stops: %s", exc.strerror)
                return
            except Exception as exc:
                log.exception("task %s failed inside the daemon", task.id)
                self._stop_robot()
                self._finish(task, TaskState.FAILED, f"internal error: {exc}")
            finally:
                with self._lock:
                    self._current = None
            if self.speech is not None:
                # A step may have found objects; let speech recognition expect their names.
                _quietly(functools.partial(self.speech.set_objects, self._known_objects() or []))
            self.on_status(
                self.idle_status()
                if self._estop_reason is None
                else f"EMERGENCY STOP latched: {self._estop_reason}; send reset to resume"
            )

    def _warm_up(self) -> None:
        pipeline = self._loaded()
        examples = [c.task for c in pipeline.profile.conventions] or [s.description for s in pipeline.profile.skills]
        started = time.monotonic()
        try:
            pipeline.translator.translate(examples[0], known_objects=self._known_objects())
        except Exception as exc:
            log.warning("the warm-up translation failed (tasks will still be tried): %s", exc)
            return
        self.warm_s = round(time.monotonic() - started, 3)
        log.info("translator warm after %.1f s", self.warm_s)

    def _run(self, task: Task) -> None:
        pipeline = self._loaded()
        start = time.monotonic()
        self.on_status(f"task {task.id}: {task.text or 'RSL program'}")
        if self._halted(task):
            return
        known = self._known_objects()
        draft = self._translate(task, known, start) if task.text is not None else self._compile(task, known, start)
        if draft is None:
            return
        verified = pipeline.verify(draft)
        if isinstance(verified, Rejected):
            self._reject(task, verified.reason, [])
            return
        task.program = verified.program
        task.plan = verified.plan.to_list()
        task.explanation = verified.explanation
        task.confidence = verified.confidence
        task.doubts = list(verified.doubts)
        self.events.publish("verified", task.id, program=task.program, plan=task.plan,
                            explanation=task.explanation, confidence=task.confidence)
        if self._halted(task) or not self._confirmed(task):
            return
        task.state = TaskState.EXECUTING
        # The plan is on disk before the first command reaches the robot.
        self.audit.write(task.record())
        self._execute(task, verified, start)

    def _recording(self, task: Task) -> Callable[[Attempted], None]:
        def record(attempt: Attempted) -> None:
            entry = attempt.to_dict()
            task.attempts.append(entry)
            self.events.publish("attempt", task.id, **entry)

        return record

    def _translate(self, task: Task, known: list[str] | None, start: float) -> Draft | None:
        assert task.text is not None
        task.state = TaskState.TRANSLATING
        self.audit.write(task.record())
        self.events.publish("translating", task.id, text=task.text)
        translated = self._loaded().translate(task.text, known, cancel=task.cancel, on_attempt=self._recording(task))
        task.mark("translate_ms", start)
        task.model = translated.model
        for name, value in translated.timings_ms.items():
            task.timings_ms[f"translator.{name}"] = value
        if len(task.attempts) < len(translated.attempts):
            # A task refused before the model was asked: its one attempt was not reported as it was made.
            task.attempts[:] = [attempt.to_dict() for attempt in translated.attempts]
        if isinstance(translated, Cancelled):
            self._finish(task, TaskState.CANCELLED, translated.reason)
            return None
        if isinstance(translated, Rejected):
            self._reject(task, translated.reason, list(translated.diagnostics))
            return None
        return translated

    def _compile(self, task: Task, known: list[str] | None, start: float) -> Draft | None:
        assert task.rsl is not None
        compiled = self._loaded().compile(task.rsl, known, self._recording(task))
        task.mark("compile_ms", start)
        if isinstance(compiled, Rejected):
            self._reject(task, compiled.reason, list(compiled.diagnostics))
            return None
        return compiled

    def _execute(self, task: Task, verified: Verified, start: float) -> None:
        def on_step(step: StepEvent) -> None:
            number = step.index  # 1-based
            if step.outcome is None:
                if "first_command_ms" not in task.timings_ms:
                    task.mark("first_command_ms", start)
                    if task.transcript and "ended_at" in task.transcript:
                        ended = float(task.transcript["ended_at"])
                        task.timings_ms["speech_end_to_first_command_ms"] = round((time.time() - ended) * 1000, 3)
                self.events.publish("executing", task.id, step=number, total=step.total, statement=step.statement)
                if self.speech is not None:
                    # Spoken feedback ("moving forward two meters") when [speech.options] feedback is on.
                    self.speech.announce(verified.plan.commands[number - 1])
                return
            outcome = {"status": step.outcome.status.value, "reason": step.outcome.reason}
            task.steps.append(
                {
                    "step": number,
                    "statement": step.statement,
                    "outcome": outcome,
                    "t_ms": round((time.monotonic() - start) * 1000.0, 3),
                }
            )
            self.audit.write(task.record())
            self.events.publish(
                "step", task.id, step=number, total=step.total, statement=step.statement, outcome=outcome
            )

        pipeline = self._loaded()
        recorder = self._recorder(task)
        on_event = on_step if recorder is None else _both(recorder.on_event, on_step)
        speech = self.speech
        if speech is not None:
            # While the robot moves, a stop-only listener hears "stop" without the wake word (barge-in).
            _quietly(lambda: speech.guard(True))
        finished = None
        try:
            finished = pipeline.execute(verified, cancel=task.cancel, on_event=on_event)
        finally:
            if speech is not None:
                _quietly(lambda: speech.guard(False))
            if recorder is not None:
                _save_pictures(task, recorder, finished.execution if finished is not None else None)
        task.mark("total_ms", start)
        state = {Status.DONE: TaskState.DONE, Status.CANCELLED: TaskState.CANCELLED}.get(finished.status,
                                                                                         TaskState.FAILED)
        self._finish(task, state, finished.reason, robot_state=finished.robot_state)

    def confirm(self, task_id: str, accept: bool, by: str) -> Task:
        """Answer the open question about `task_id`; raises `not_waiting` when none is open."""
        task = self.task(task_id)
        with self._lock:
            question = self._questions.get(task_id)
        if question is None or not question.answer(accept, by):
            raise ProtocolError(
                "not_waiting",
                f"task {task_id} is not waiting for a confirmation (it is {task.state.value})",
                "answer only after a `confirm` event, within its timeout_s",
            )
        return task

    def _confirmed(self, task: Task) -> bool:
        """Whether the plan may run: asks the person first when the confirm policy says so."""
        policy = self.config.translator.confirm
        unsure = task.text is not None and (task.confidence is None or task.confidence < UNSURE_BELOW)
        if policy == "never" or (policy == "unsure" and not unsure):
            self._say(task.explanation, wait_s=_EXPLAIN_WAIT_S)
            return True
        question = Question(task.id)
        timeout = self.config.translator.confirm_timeout
        with self._lock:
            self._questions[task.id] = question
        try:
            task.state = TaskState.CONFIRMING
            self.audit.write(task.record())
            self.events.publish("confirm", task.id, text=task.text, explanation=task.explanation,
                                confidence=task.confidence, reasons=task.doubts, timeout_s=timeout)
            self._say(f"Should I {task.explanation}? Say yes or no.")
            answer = question.wait(timeout, task.cancel)
        finally:
            with self._lock:
                self._questions.pop(task.id, None)
        if answer.by:
            self.events.publish("answered", task.id, accepted=answer.accepted, by=answer.by)
        if not answer.accepted:
            self._finish(task, TaskState.CANCELLED, answer.reason)
            return False
        task.confirmed_by = answer.by
        return True

    def _say(self, text: str, *, wait_s: float = 0.0) -> None:
        """Spoken feedback, when speech is on and its feedback is enabled; never fails the task."""
        speech = self.speech
        if speech is not None:
            _quietly(lambda: speech.say(text, wait_s=wait_s))

    # -- helpers ---------------------------------------------------------------------------

    def _loaded(self) -> Pipeline:
        assert self.pipeline is not None, "load() sets up the pipeline before the worker starts"
        return self.pipeline

    def _recorder(self, task: Task) -> Recorder | None:
        """Pictures of this task's run when [robot] record names a directory; they never fail a task."""
        if not self.config.robot.record:
            return None
        try:
            from agent.record import Recorder

            return Recorder(Path(self.config.robot.record).expanduser() / task.id, self._loaded().robot, gif=True)
        except Exception as exc:
            log.warning("task %s: no pictures: %s", task.id, exc)
            return None

    def _halted(self, task: Task) -> bool:
        """Finish `task` as cancelled if it was cancelled or an emergency stop is latched."""
        with self._lock:
            latched = self._estop_reason
        if latched is not None and not task.cancel.is_set():
            # Taken off the queue in the instant the emergency stop drained it.
            task.cancel.set(f"emergency stop: {latched}")
        if not task.cancel.is_set():
            return False
        self._finish(task, TaskState.CANCELLED, task.cancel.reason)
        return True

    def _reject(self, task: Task, reason: str, diagnostics: list[dict[str, Any]]) -> None:
        with self._lock:
            if task.state.finished:
                return
            task.state = TaskState.REJECTED
            task.reason = reason
        self.audit.write(task.record(), final=True)
        self.events.publish("rejected", task.id, reason=reason, diagnostics=diagnostics)

    def _finish(self, task: Task, state: TaskState, reason: str, *, robot_state: dict[str, Any] | None = None) -> None:
        with self._lock:
            if task.state.finished:
                return
            task.state = state
            task.reason = reason
        self.audit.write(task.record(), final=True)
        if state is TaskState.DONE:
            self.events.publish("done", task.id, state=robot_state)
        else:
            self.events.publish(state.value, task.id, reason=reason, state=robot_state)

    def _remember(self, task: Task) -> None:
        self._tasks[task.id] = task
        while len(self._tasks) > self.config.tasks.history + self.queue.capacity + 1:
            oldest = next(iter(self._tasks.values()))
            if not oldest.state.finished:
                break
            self._tasks.popitem(last=False)

    def _known_objects(self) -> list[str] | None:
        """The objects programs may name (`Pipeline.known_objects`); None also when the robot cannot say."""
        try:
            return self._loaded().known_objects()
        except Exception as exc:
            log.warning("cannot read the known objects from the robot: %s", exc)
            return None

    def _stop_robot(self) -> None:
        if self.robot is None:
            return
        try:
            self.robot.stop()
        except Exception:
            log.exception("robot.stop() failed")

    def _start_speech(self) -> None:
        try:
            from agent.daemon.voice import start_speech

            self.speech = start_speech(
                self.config.speech.options, self.config.robot.profile, self._on_transcript, self._on_speech_event
            )
        except Exception as exc:
            self.speech = None
            self.speech_problem = f"{type(exc).__name__}: {exc}"
            log.warning("speech input is off: %s; the socket API keeps working", self.speech_problem)

    def _on_transcript(self, transcript: Transcript) -> None:
        text = str(transcript.text).strip()
        if not text:
            return
        from agent.speech.lexicon import is_stop_command, yes_or_no

        if is_stop_command(text):
            cancelled = self.halt(f"stopped by voice: {text!r}")
            log.info("heard %r: robot stopped, cancelled %s", text, cancelled or "nothing")
            self.events.publish("speech", None, state="stop", detail={"text": text, "cancelled": cancelled})
            return
        if transcript.source == "barge_in":
            return  # the stop listener only ever stops; nothing it hears becomes a task or an answer
        reply = yes_or_no(text)
        with self._lock:
            open_questions = list(self._questions)
        if reply is not None and open_questions:
            self.confirm(open_questions[0], reply, "voice")
            log.info("heard %r: task %s %s", text, open_questions[0], "accepted" if reply else "declined")
            return
        heard = transcript.to_dict()

        def announce(task: Task) -> None:
            task.transcript = heard
            self.events.publish("heard", task.id, **heard)

        try:
            self.submit(source="voice", text=text[: self.config.api.max_task_chars], before_queue=announce)
        except ProtocolError as exc:
            log.warning("spoken task %r not queued: %s", text, exc.message)
            self.events.publish("speech", None, state="dropped", detail={"text": text, "reason": exc.message})

    def _on_speech_event(self, event: SpeechEvent) -> None:
        self.events.publish("speech", None, state=event.kind, detail=event.to_dict())


def _needs_restart(translator: TranslatorConfig) -> TranslatorConfig:
    """The translator settings that take a restart: all but the confirm policy, which applies at once."""
    return dataclasses.replace(translator, confirm="", confirm_timeout=0.0)


def _save_pictures(task: Task, recorder: Recorder, result: ExecutionResult | None) -> None:
    try:
        pictures = recorder.finish(result, title=task.text or "RSL program")
        log.info("task %s: %d picture(s) in %s", task.id, len(pictures), pictures[0].parent)
    except Exception as exc:
        log.warning("task %s: the pictures were not saved: %s", task.id, exc)


def _both(pictures: Callable[[StepEvent], None], on_step: Callable[[StepEvent], None]) -> Callable[[StepEvent], None]:
    def call(event: StepEvent) -> None:
        try:
            pictures(event)
        except Exception as exc:  # a picture is never worth a step
            log.warning("a picture of step %s was not saved: %s", event.index, exc)
        on_step(event)

    return call


def _quietly(action: Callable[[], Any]) -> None:
    try:
        action()
    except Exception:
        log.exception("error while shutting down")


def _load_profile(path: str) -> Profile:
    from rsl.profile import ProfileError, load_profile

    try:
        return load_profile(path or None)
    except ProfileError as exc:
        raise StartupError(f"{exc}\n  = help: fix the profile or set robot.profile in the config") from exc


def _load_translator(config: Config, profile: Profile) -> TaskTranslator:
    settings = config.translator
    try:
        from agent.translate import Translator

        return Translator.load(
            profile,
            model=settings.model or None,
            adapter=settings.adapter or None,
            grammar=settings.grammar,
            max_passes=settings.max_passes,
            endpoint=settings.endpoint or None,
        )
    except Exception as exc:
        raise StartupError(
            f"cannot load the translation model: {exc}\n"
            "  = help: check translator.model and translator.adapter in the config; "
            "`nrtrans models list` shows the models installed here"
        ) from exc


def _open_robot(config: Config, profile: Profile) -> Robot:
    settings = config.robot
    try:
        from agent.backends import open_robot

        options: dict[str, Any] = {}
        if settings.backend == "sim":
            options = {"scene": settings.scene or None, "realtime_factor": settings.realtime_factor}
        return open_robot(settings.backend, profile, **options)
    except Exception as exc:
        raise StartupError(
            f"cannot open the {settings.backend} backend: {exc}\n"
            "  = help: check [robot] in the config, or use --backend sim"
        ) from exc
