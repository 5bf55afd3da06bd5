"""One task's path: text (or an RSL program) -> translation -> verified plan -> outcome.

Each stage takes and returns typed, frozen records, and none of them knows
about the socket, the queue or the audit log: the daemon's worker
(agent/daemon/service.py) calls the stages in order and records what each
returned, and a test can drive the same stages with the real translator and
the real simulator. Only a `Verified` plan reaches `execute`.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from agent.daemon.world_checks import check_world
from agent.executor import ExecutionResult, StepEvent, execute
from agent.robot import CancelToken, Robot, Status
from agent.translate.engine import CancelFlag, GenerationCancelled
from agent.translate.explain import capabilities, explain
from agent.translate.result import Attempt, TranslationResult
from rsl.compiler import compile_program
from rsl.plan import Plan
from rsl.profile import Profile


class TaskTranslator(Protocol):
    """What the pipeline needs of a translator (`agent.translate.Translator`, local or over HTTP)."""

    model_name: str

    def translate(self, task: str, *, known_objects: Collection[str] | None = None,
                  on_attempt: Callable[[Attempt], None] | None = None,
                  cancel: CancelFlag | None = None) -> TranslationResult:
        """Every attempt goes to `on_attempt` as it is made; `cancel` set mid-way raises GenerationCancelled."""

    def close(self) -> None: ...


@dataclass(frozen=True)
class Attempted:
    """One candidate program, numbered from 1, and what the compiler said about it."""

    number: int
    program: str
    diagnostics: tuple[dict[str, Any], ...]

    def to_dict(self) -> dict[str, Any]:
        return {"pass": self.number, "program": self.program, "diagnostics": list(self.diagnostics)}


@dataclass(frozen=True)
class Draft:
    """A plan the compiler verified, before it is checked against the robot's world."""

    plan: Plan
    attempts: tuple[Attempted, ...] = ()
    model: str | None = None
    confidence: float | None = None
    doubts: tuple[str, ...] = ()
    timings_ms: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Verified:
    """A plan that may run: compiled, checked against the world, and put in words."""

    plan: Plan
    program: str
    explanation: str
    confidence: float | None = None
    doubts: tuple[str, ...] = ()


@dataclass(frozen=True)
class Rejected:
    """No plan: nothing moved. `diagnostics` are the last attempt's."""

    reason: str
    diagnostics: tuple[dict[str, Any], ...] = ()
    attempts: tuple[Attempted, ...] = ()
    model: str | None = None
    timings_ms: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Cancelled:
    reason: str
    attempts: tuple[Attempted, ...] = ()
    model: str | None = None
    timings_ms: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Finished:
    """How a verified plan's run ended, with the robot's state after it."""

    status: Status
    reason: str
    robot_state: dict[str, Any] | None
    execution: ExecutionResult


class Pipeline:
    """The stages for one robot profile, translator and robot."""

    def __init__(self, profile: Profile, translator: TaskTranslator, robot: Robot) -> None:
        self.profile = profile
        self.translator = translator
        self.robot = robot

    def translate(self, text: str, known: list[str] | None, *, cancel: CancelToken,
                  on_attempt: Callable[[Attempted], None] = lambda _a: None) -> Draft | Rejected | Cancelled:
        """`on_attempt` hears each attempt as it is made; a task refused before the model has its one
        attempt only in the returned record's `attempts`."""
        reported = 0

        def report(attempt: Attempt) -> None:
            nonlocal reported
            reported += 1
            on_attempt(_numbered(reported, attempt))

        try:
            result = self.translator.translate(text, known_objects=known, on_attempt=report, cancel=cancel)
        except GenerationCancelled:
            # Cut off mid-generation: a cancel or an estop need not wait for the translation to end.
            return Cancelled(cancel.reason)
        attempts = tuple(_numbered(number, a) for number, a in enumerate(result.attempts, 1))
        if cancel.is_set():
            return Cancelled(cancel.reason, attempts, result.model, result.timings_ms)
        if not result.verified or result.plan is None:
            last = attempts[-1].diagnostics if attempts else ()
            reason = (f"not understood as a task for this robot; nothing moved. It can: {capabilities(self.profile)}"
                      if result.refused else f"no verified program after {result.passes} attempt(s); nothing moved")
            return Rejected(reason, last, attempts, result.model, result.timings_ms)
        return Draft(result.plan, attempts, result.model, result.confidence, result.doubts, result.timings_ms)

    def compile(self, rsl: str, known: list[str] | None,
                on_attempt: Callable[[Attempted], None] = lambda _a: None) -> Draft | Rejected:
        result = compile_program(rsl, self.profile, known)
        attempt = Attempted(1, rsl, tuple(d.to_dict() for d in result.diagnostics))
        on_attempt(attempt)
        if not result.ok or result.plan is None:
            return Rejected("the program does not compile; nothing moved", attempt.diagnostics, (attempt,))
        return Draft(result.plan, (attempt,))

    def verify(self, draft: Draft) -> Verified | Rejected:
        """Check the plan against what the robot knows of its world, and put it in words."""
        world = check_world(draft.plan, self.profile, self.robot)
        if world.plan is None:
            return Rejected(world.refusal)
        return Verified(world.plan, world.plan.to_rsl(), explain(world.plan, self.profile), draft.confidence,
                        draft.doubts)

    def execute(self, verified: Verified, *, cancel: CancelToken,
                on_event: Callable[[StepEvent], None] = lambda _e: None) -> Finished:
        result = execute(verified.plan, self.robot, self.profile, cancel=cancel, on_event=on_event)
        state = result.final_state.to_dict() if result.final_state is not None else None
        if result.status is Status.DONE:
            return Finished(Status.DONE, "", state, result)
        if result.status is Status.CANCELLED:
            return Finished(Status.CANCELLED, cancel.reason or _last_reason(result), state, result)
        return Finished(Status.FAILED, _last_reason(result) or "a step failed", state, result)

    def known_objects(self) -> list[str] | None:
        """The objects programs may name; None leaves names to the robot to check.

        Until the robot has perceived anything, every name is left open:
        rejecting "grasp the cup" before the robot has looked would refuse
        tasks it can carry out, since backends look for an object on demand.
        """
        return [name for name, _x, _y in self.robot.state().known_objects] or None


def _numbered(number: int, attempt: Attempt) -> Attempted:
    return Attempted(number, attempt.program, tuple(d.to_dict() for d in attempt.diagnostics))


def _last_reason(result: ExecutionResult) -> str:
    return next((outcome.reason for outcome in reversed(result.outcomes) if outcome.reason), "")
