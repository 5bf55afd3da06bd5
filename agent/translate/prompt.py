"""Prompts: the fixed system text, shots picked by similarity, the task, and repair feedback.

The system text comes first and never changes for a profile, so llama.cpp
keeps its KV state across requests and a request only evaluates the shots
and the task. Shots are chosen per task by word overlap: the closest one
goes last, nearest the task.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from importlib import resources

from rsl.compiler import compile_program
from rsl.describe import language_description
from rsl.diagnostics import Diagnostic
from rsl.profile import Profile

_WORD = re.compile(r"-?\d*\.?\d+|[a-z_]+")
_STOP = frozenset({"the", "a", "an", "to", "and", "of", "by", "m", "rad", "then"})


@dataclass(frozen=True)
class Shot:
    task: str
    program: str  # canonical, one statement per line, ending in "\n"


def system_text(profile: Profile) -> str:
    return (
        "You translate tasks for a robot into RSL programs.\n\n"
        f"{language_description(profile)}\n"
        "Write only RSL statements, one per line, and end the program with an empty line. "
        "Copy numbers from the task exactly; they are already in metres and radians.\n\n"
    )


def load_shots(profile: Profile) -> tuple[Shot, ...]:
    """The shot bank for `profile`: the bundled examples that compile on it, plus its conventions."""
    raw = tomllib.loads((resources.files("agent.translate") / "shots.toml").read_text("utf-8"))
    pairs: list[tuple[str, str]] = [(str(t), str(p)) for t, p in raw["shots"]]
    pairs.extend((c.task, c.program) for c in profile.conventions if c.task and c.program)
    shots = []
    for task, program in pairs:
        result = compile_program(program, profile)
        if result.ok and result.plan is not None:
            shots.append(Shot(task=task, program=result.plan.to_rsl()))
    return tuple(shots)


def _features(text: str) -> set[str]:
    words = {("<n>" if w[0].isdigit() or w[0] in "-." else w) for w in _WORD.findall(text)}
    return words - _STOP


def pick_shots(bank: Sequence[Shot], task: str, count: int) -> list[Shot]:
    """The `count` shots most similar to `task`, least similar first."""
    if count <= 0:
        return []
    wanted = _features(task)

    def score(shot: Shot) -> float:
        have = _features(shot.task)
        return len(wanted & have) / (len(wanted | have) or 1)

    ranked = sorted(bank, key=score, reverse=True)[:count]
    return list(reversed(ranked))


def completion_prompt(system: str, shots: Sequence[Shot], task: str) -> str:
    body = "".join(f"Task: {s.task}\nRSL:\n{s.program}\n" for s in shots)
    return f"{system}{body}Task: {task}\nRSL:\n"


def feedback(program: str, diagnostics: Sequence[Diagnostic]) -> str:
    """What follows a rejected program in the prompt, ending where the model writes the fix."""
    lines = "\n".join(f"- {d.brief()}" for d in diagnostics)
    body = program if program.endswith("\n") else program + "\n"
    return f"{body}\nThe RSL compiler rejected that program:\n{lines}\nCorrected RSL:\n"


def chat_prompt(template: str, bos: str, eos: str, system: str, shots: Sequence[Shot], task: str) -> str:
    """The same conversation through a model's own chat template."""
    from llama_cpp.llama_chat_format import Jinja2ChatFormatter

    messages: list[dict[str, str]] = [{"role": "system", "content": system.strip()}]
    for shot in shots:
        messages.append({"role": "user", "content": shot.task})
        messages.append({"role": "assistant", "content": shot.program})
    messages.append({"role": "user", "content": task})
    formatter = Jinja2ChatFormatter(template=template, eos_token=eos, bos_token=bos)
    rendered = formatter(messages=messages).prompt  # type: ignore[arg-type]
    return rendered[len(bos):] if bos and rendered.startswith(bos) else rendered
