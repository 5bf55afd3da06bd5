"""Run a verified plan on a robot, one step at a time.

The executor is the last gate before the motors: it only ever receives a
`Plan` (which only the compiler makes), runs its steps in order, stops at the
first step that does not finish, and honours a cancel token between steps and,
through the backend, during a motion. Every step runs under a watchdog derived
from its size and the profile's speed limits, so a backend that stalls is
stopped and the step fails with a reason instead of hanging the daemon.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass

from agent.robot import CancelToken, Outcome, Pose, Robot, RobotState, Status
from rsl.plan import Command, ObjectRef, Plan
from rsl.profile import Primitive, Profile, RosBinding, Skill

log = logging.getLogger(__name__)

# Seconds of wall time the watchdog grants beyond a step's own budget, so a
# backend that enforces the budget itself reports its own, more precise reason.
WATCHDOG_GRACE = 2.0


@dataclass(frozen=True)
class StepEvent:
    index: int  # 1-based
    total: int
    statement: str  # canonical RSL, e.g. `kw 1.5;`
    outcome: Outcome | None  # None: the step has just started


@dataclass(frozen=True)
class ExecutionResult:
    status: Status
    outcomes: tuple[Outcome, ...]  # one per step that ran (or was cancelled before it ran)
    final_state: RobotState | None  # None only when the backend could not report its state

    @property
    def ok(self) -> bool:
        return self.status is Status.DONE


def travel_time(amount: float, speed: float, accel: float) -> float:
    """Seconds to cover `amount` from rest to rest with a trapezoidal speed profile."""
    amount = abs(amount)
    if amount <= 0:
        return 0.0
    ramp = speed * speed / accel  # distance spent speeding up and slowing down
    if amount < ramp:
        return 2.0 * math.sqrt(amount / accel)
    return amount / speed + speed / accel


def _workspace_diagonal(profile: Profile) -> float:
    (xlo, xhi), (ylo, yhi) = profile.workspace["x"], profile.workspace["y"]
    return math.hypot(xhi - xlo, yhi - ylo)


def drive_time(distance: float, profile: Profile) -> float:
    """Seconds for a turn to face the target (at most half a turn) and a straight drive."""
    motion = profile.motion
    return (travel_time(math.pi, motion.max_angular_speed, motion.max_angular_accel)
            + travel_time(distance, motion.max_linear_speed, motion.max_linear_accel))


def step_timeout(command: Command, profile: Profile, start: RobotState | None = None) -> float:
    """The time budget of one step: its nominal duration at the profile's limits plus `timeout_margin`.

    The budget follows the skill's binding, never its keyword. Navigating and
    approaching depend on where the robot is; with `start` (the state before
    the step) the budget uses the real distance, without it the workspace's
    diagonal, which is always enough.
    """
    motion = profile.motion
    margin = motion.timeout_margin
    numbers = [a.value for a in command.args if not isinstance(a, ObjectRef)]
    skill = profile.skill(command.skill)
    binding = skill.binding if skill is not None else None
    primitive = binding.name if isinstance(binding, Primitive) else None
    if primitive == "drive":
        return travel_time(numbers[0], motion.max_linear_speed, motion.max_linear_accel) + margin
    if primitive == "turn":
        return travel_time(numbers[0], motion.max_angular_speed, motion.max_angular_accel) + margin
    if primitive in ("pan", "tilt"):
        return abs(numbers[0]) / motion.max_head_speed + margin
    if primitive == "navigate" and skill is not None:
        x, y = navigate_point(skill, numbers)
        distance = (math.hypot(x - start.pose.x, y - start.pose.y) if start is not None
                    else _workspace_diagonal(profile))
        # A final turn-in-place may follow when the robot reverses onto the point.
        return drive_time(distance, profile) + margin
    if primitive == "approach_object":
        known = _distance_to_known(command.object(0), start.pose, start) if start is not None else None
        distance = known if known is not None else _workspace_diagonal(profile)
        # Two turns: to face the stand-off point, then to face the object.
        return drive_time(distance, profile) + travel_time(math.pi, motion.max_angular_speed,
                                                           motion.max_angular_accel) + margin
    # perceive, grasp and ROS 2 bindings: the margin, plus a second per argument for skills
    # that act on each, plus the time a joint trajectory is given to reach its point.
    moving = binding.duration if isinstance(binding, RosBinding) else 0.0
    return margin + 2.0 + len(command.args) + moving


def navigate_point(skill: Skill, numbers: list[float]) -> tuple[float, float]:
    """The (x, y) a `navigate` skill's arguments name, by each parameter's axis."""
    by_axis = {p.axis: value for p, value in zip(skill.params, numbers, strict=True)}
    return by_axis["x"], by_axis["y"]


def _distance_to_known(name: str, pose: Pose, state: RobotState) -> float | None:
    for known, x, y in state.known_objects:
        if known == name:
            return math.hypot(x - pose.x, y - pose.y)
    return None


def _arguments(command: Command) -> tuple[float | str, ...]:
    return tuple(a.name if isinstance(a, ObjectRef) else a.value for a in command.args)


def _state(robot: Robot) -> RobotState | None:
    try:
        return robot.state()
    except Exception:
        return None


def _backend_name(robot: Robot) -> str:
    return str(getattr(robot, "backend_name", type(robot).__name__))


def execute(plan: Plan, robot: Robot, profile: Profile, *, cancel: CancelToken | None = None,
            on_event: Callable[[StepEvent], None] | None = None) -> ExecutionResult:
    """Run `plan` on `robot` step by step; stop at the first step that is not done."""
    cancel = cancel or CancelToken()
    total = len(plan.commands)
    outcomes: list[Outcome] = []

    def emit(event: StepEvent) -> None:
        if on_event is None:
            return
        try:
            on_event(event)
        except Exception:
            # Progress reporting must never leave the robot between steps of a half-run plan.
            log.exception("the step event handler failed on %s; the plan goes on", event)

    for index, command in enumerate(plan.commands, start=1):
        statement = command.to_rsl()
        if cancel.is_set():
            outcome = Outcome.cancelled(cancel.reason or "cancelled")
            outcomes.append(outcome)
            emit(StepEvent(index, total, statement, outcome))
            break
        emit(StepEvent(index, total, statement, None))
        outcome = _run_step(command, statement, robot, profile, cancel)
        outcomes.append(outcome)
        emit(StepEvent(index, total, statement, outcome))
        if not outcome.ok:
            break
    finished = len(outcomes) == total and all(o.ok for o in outcomes)
    status = Status.DONE if finished else outcomes[-1].status
    return ExecutionResult(status=status, outcomes=tuple(outcomes), final_state=_state(robot))


def _run_step(command: Command, statement: str, robot: Robot, profile: Profile,
              cancel: CancelToken) -> Outcome:
    skill = profile.skill(command.skill)
    if skill is None or skill.binding is None:
        why = (f"profile {profile.name} has no skill `{command.skill}`" if skill is None
               else f"the skill `{command.skill}` declares no binding in profile {profile.name}")
        return Outcome.failed(f"`{statement}` cannot run: {why}, so no backend knows what it does. "
                              "Give it a `binding` (a robot primitive or a ROS 2 topic, service or "
                              "joint trajectory; docs/skills.md)")
    budget = step_timeout(command, profile, _state(robot))
    # Wall-clock watchdog; a simulator slower than real time stretches it.
    scale = float(getattr(robot, "timeout_scale", 1.0))
    step_token = CancelToken()
    timed_out = threading.Event()

    def forward_cancel() -> None:
        # The caller's token and the watchdog both end the step through one token.
        while not step_token.is_set():
            if cancel.wait(0.01):
                step_token.set(cancel.reason or "cancelled")
                return

    def expire() -> None:
        timed_out.set()
        step_token.set("timeout")
        robot.stop()

    relay = threading.Thread(target=forward_cancel, name="nrtrans-cancel-relay", daemon=True)
    watchdog = threading.Timer(budget * scale + WATCHDOG_GRACE, expire)
    watchdog.daemon = True
    relay.start()
    watchdog.start()
    try:
        outcome = robot.perform(skill, _arguments(command), cancel=step_token)
    except Exception as exc:
        robot.stop()
        outcome = Outcome.failed(f"`{statement}` failed inside the {_backend_name(robot)} backend: "
                                 f"{type(exc).__name__}: {exc}; the robot was stopped")
    finally:
        watchdog.cancel()
        step_token.set(step_token.reason or "step over")
        relay.join()
    if timed_out.is_set() and not outcome.ok:
        return Outcome.failed(f"`{statement}` timed out after {budget:.1f} s (its budget from the step's size, "
                              "the profile's speed limits and timeout_margin); the robot was stopped")
    if not isinstance(outcome, Outcome):
        return Outcome.failed(f"`{statement}`: the {_backend_name(robot)} backend returned {outcome!r}, "
                              "not an Outcome")
    return outcome
