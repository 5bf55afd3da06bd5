"""The prompt format the RSL adapter is trained on, shared by training and runtime.

The adapter learns to continue `adapter_prompt(task)` with the canonical RSL
program: one `kw a, b;` statement per line, closed by an empty line, exactly
the text `rsl.grammar.to_gbnf` accepts. So the grammar, the trained adapter and
the runtime prompt must agree on this one function; change it only together
with a retrain.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

# Bumped whenever the prompt text changes; the adapter card records it and the
# runtime can refuse an adapter trained on another format.
PROMPT_VERSION = 1

ADAPTER_FILE = "rsl-default-gemma3-270m-q4km.gguf"
CARD_FILE = "rsl-default-gemma3-270m-q4km.json"


def _adapters_dir() -> Path:
    return Path(str(resources.files("models"))) / "adapters"


DEFAULT_ADAPTER: Path = _adapters_dir() / ADAPTER_FILE
DEFAULT_ADAPTER_CARD: Path = _adapters_dir() / CARD_FILE

# The program ends with an empty line: the last statement's "\n" plus this one.
PROGRAM_END = "\n"


def adapter_prompt(normalized_task: str) -> str:
    """The text the model continues with an RSL program for `normalized_task`.

    `normalized_task` is the output of `agent.normalize.normalize_task`; the
    adapter was trained on normalized text only.
    """
    task = " ".join(normalized_task.split())
    return f"Task: {task}\nRSL:\n"


def training_text(normalized_task: str, program: str) -> tuple[str, str]:
    """(prompt, completion) for one training pair; `program` is canonical RSL."""
    body = program if program.endswith("\n") else program + "\n"
    return adapter_prompt(normalized_task), body + PROGRAM_END
