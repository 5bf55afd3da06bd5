"""Keep the evaluation suite out of the training data.

A training task that equals an eval task after normalization, or is a close
paraphrase of one (difflib ratio above `THRESHOLD`), would make `nrtrans eval`
measure memory instead of skill, so the generator drops it.
"""

from __future__ import annotations

import difflib
import tomllib
from collections.abc import Callable, Iterable
from importlib import resources
from pathlib import Path

from agent.normalize import normalize_task

THRESHOLD = 0.9


def suite_path() -> Path:
    return Path(str(resources.files("agent"))) / "evalsuite" / "suite.toml"


def eval_tasks(path: Path | None = None) -> list[str]:
    """The eval suite's task texts, as written; none when there is no suite."""
    source = path or suite_path()
    if not source.is_file():
        return []
    with source.open("rb") as handle:
        data = tomllib.load(handle)
    return [str(entry["task"]) for entry in data.get("task", []) if "task" in entry]


def is_close(candidate: str, reference: str, threshold: float = THRESHOLD) -> bool:
    """Whether two normalized tasks are the same or a close paraphrase."""
    if candidate == reference:
        return True
    matcher = difflib.SequenceMatcher(None, candidate, reference, autojunk=False)
    return (matcher.real_quick_ratio() > threshold and matcher.quick_ratio() > threshold
            and matcher.ratio() > threshold)


def held_out_filter(tasks: Iterable[str], threshold: float = THRESHOLD) -> Callable[[str], bool]:
    """A predicate on normalized training tasks: true for those too close to any of `tasks`."""
    references = sorted({normalize_task(t) for t in tasks})

    def excluded(normalized: str) -> bool:
        return any(is_close(normalized, reference, threshold) for reference in references)

    return excluded
