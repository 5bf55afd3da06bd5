"""Loading the suite and deciding whether a plan does what a task asked.

A plan is accepted when it matches one of the task's accepted programs after
consecutive moves of one kind are merged (`forward 1; forward 1;` is
`forward 2;`), with every number within a tolerance. A task marked
`refuse = true` is not a robot task: it is done right only when no plan
comes back.

A suite file may name its own groups in a top-level `groups = [...]`; the
evaluation suite uses `GROUPS`.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from rsl.compiler import compile_program
from rsl.plan import Command, ObjectRef, Plan, Quantity
from rsl.profile import Profile

GROUPS = ("simple", "ambiguous", "multi-step", "complex", "units", "asr-noise")
# 2 cm and 0.02 rad (about 1 degree): tighter than the robot can act on.
TOLERANCE = 0.02


@dataclass(frozen=True)
class EvalTask:
    group: str
    task: str
    accept: tuple[str, ...]
    objects: tuple[str, ...] | None = None
    holdout: bool = False
    refuse: bool = False


class SuiteError(ValueError):
    """A suite file that cannot be used, with where and why."""


def suite_path() -> Path:
    return Path(str(resources.files("agent.evalsuite") / "suite.toml"))


def load_suite(path: str | Path | None = None, profile: Profile | None = None) -> tuple[EvalTask, ...]:
    """All tasks; with `profile`, every accepted program is checked to compile on it."""
    source = Path(path) if path is not None else suite_path()
    try:
        data = tomllib.loads(source.read_text("utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise SuiteError(f"cannot load the evaluation suite {source}: {exc}") from exc
    groups = tuple(str(g) for g in data.get("groups", GROUPS))
    tasks = []
    for index, raw in enumerate(data.get("task", []), start=1):
        group = str(raw.get("group", ""))
        if group not in groups:
            raise SuiteError(f"{source}: task #{index} has group {group!r}; use one of {', '.join(groups)}")
        objects = raw.get("objects")
        task = EvalTask(group=group, task=str(raw["task"]), accept=tuple(str(a) for a in raw["accept"]),
                        objects=None if objects is None else tuple(str(o) for o in objects),
                        holdout=bool(raw.get("holdout", False)), refuse=bool(raw.get("refuse", False)))
        if task.refuse == bool(task.accept):
            raise SuiteError(f"{source}: task #{index} ({task.task!r}) must either accept programs or be "
                             "`refuse = true` with `accept = []`")
        if profile is not None:
            for program in task.accept:
                result = compile_program(program, profile, task.objects)
                if not result.ok:
                    details = "; ".join(d.brief() for d in result.diagnostics)
                    raise SuiteError(f"{source}: task #{index} ({task.task!r}) accepts a program that does not "
                                     f"compile: {program!r}: {details}")
        tasks.append(task)
    return tuple(tasks)


def accepts(task: EvalTask, plan: Plan | None, profile: Profile) -> bool:
    """True when `plan` does what one of the task's accepted programs does, or is None for a non-task."""
    if plan is None or task.refuse:
        return plan is None and task.refuse
    mergeable = _mergeable(profile)
    got = _merged(plan.commands, mergeable)
    for program in task.accept:
        expected = compile_program(program, profile, task.objects).plan
        if expected is not None and _same(got, _merged(expected.commands, mergeable)):
            return True
    return False


def _mergeable(profile: Profile) -> frozenset[str]:
    """Skills whose one number adds up when repeated: relative moves, not goto or grasp."""
    return frozenset(s.keyword for s in profile.skills
                     if len(s.params) == 1 and s.params[0].kind == "number" and not s.params[0].is_coordinate)


def _merged(commands: tuple[Command, ...], mergeable: frozenset[str]) -> list[tuple[str, tuple[float | str, ...]]]:
    out: list[tuple[str, tuple[float | str, ...]]] = []
    for command in commands:
        args = tuple(a.value if isinstance(a, Quantity) else a.name for a in command.args
                     if isinstance(a, Quantity | ObjectRef))
        if out and command.skill in mergeable and out[-1][0] == command.skill:
            previous = out[-1][1][0]
            assert isinstance(previous, float) and isinstance(args[0], float)
            out[-1] = (command.skill, (previous + args[0],))
        else:
            out.append((command.skill, args))
    return out


def _same(a: list[tuple[str, tuple[float | str, ...]]], b: list[tuple[str, tuple[float | str, ...]]]) -> bool:
    if len(a) != len(b):
        return False
    for (skill_a, args_a), (skill_b, args_b) in zip(a, b, strict=True):
        if skill_a != skill_b or len(args_a) != len(args_b):
            return False
        for x, y in zip(args_a, args_b, strict=True):
            if isinstance(x, float) and isinstance(y, float):
                if abs(x - y) > TOLERANCE:
                    return False
            elif x != y:
                return False
    return True
