"""The prompt format the RSL adapter is trained on, shared by training and runtime.

The adapter learns to continue `adapter_prompt(task, profile)` with the canonical RSL
program: one `kw a, b;` statement per line, closed by an empty line, exactly
the text `rsl.grammar.to_gbnf` accepts. So the grammar, the trained adapter and
the runtime prompt must agree on this one function; change it only together
with a retrain.
"""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

from agent.normalize import normalize_task
from rsl.compiler import compile_program
from rsl.plan import ObjectRef
from rsl.profile import Profile

# Bumped whenever the prompt text changes; the adapter card records it and the
# runtime can refuse an adapter trained on another format.
PROMPT_VERSION = 3

ADAPTER_FILE = "rsl-default-gemma3-270m-q4km.gguf"
CARD_FILE = "rsl-default-gemma3-270m-q4km.json"


def _adapters_dir() -> Path:
    return Path(str(resources.files("models"))) / "adapters"


DEFAULT_ADAPTER: Path = _adapters_dir() / ADAPTER_FILE
DEFAULT_ADAPTER_CARD: Path = _adapters_dir() / CARD_FILE

# The program ends with an empty line: the last statement's "\n" plus this one.
PROGRAM_END = "\n"


def convention_notes(normalized_task: str, profile: Profile) -> list[str]:
    """The profile's conventions for the vague phrases the task uses, one note each.

    A whole command ("look around") is noted with its program, an amount ("a
    little") with its meaning, and so is a command about an object ("go get"),
    whose example program names one object where the task may name another.
    The adapter learns to follow the notes, so the profile, not the training
    data alone, decides what a vague phrase does,
    and a phrase the data rarely shows on its own still gets its program.
    """
    notes = []
    for convention in profile.conventions:
        phrase = normalize_task(convention.phrase)
        if phrase != convention.phrase.lower():
            continue  # the normalizer already writes it as a number ("a full circle" -> "6.2832 rad")
        if not phrase or not re.search(rf"\b{re.escape(phrase)}\b", normalized_task):
            continue
        as_program = convention.whole_command and not program_objects(convention.program, profile)
        meaning = " ".join(convention.program.split()) if as_program else convention.meaning
        notes.append(f"{phrase} = {meaning}")
    return notes


def program_objects(program: str, profile: Profile) -> list[str]:
    """The object names a convention's example program passes ("approach cup; grasp cup;" -> cup), read
    by the compiler."""
    plan = compile_program(program, profile).plan
    return [arg.name for command in plan or () for arg in command.args if isinstance(arg, ObjectRef)]


def adapter_prompt(normalized_task: str, profile: Profile) -> str:
    """The text the model continues with an RSL program for `normalized_task`.

    `normalized_task` is the output of `agent.normalize.normalize_task`; the
    adapter was trained on normalized text only.
    """
    task = " ".join(normalized_task.split())
    notes = "".join(f"Note: {note}\n" for note in convention_notes(task, profile))
    return f"Task: {task}\n{notes}RSL:\n"


def training_text(prompt: str, program: str) -> tuple[str, str]:
    """(prompt, completion) for one training pair; `program` is canonical RSL."""
    body = program if program.endswith("\n") else program + "\n"
    return prompt, body + PROGRAM_END
