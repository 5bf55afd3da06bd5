"""Training pairs encoded to token IDs, in a file that carries training to another machine.

transformers builds its tokenizer from the GGUF, and only some versions split text as llama.cpp does
(5.24 does; 5.17, the one on a GPU machine here, does not). Encoding where the tokenizer agrees and
training elsewhere from the IDs gives an adapter that works with llama.cpp, trained on any machine.
"""

from __future__ import annotations

import gzip
import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

EXAMPLES_FORMAT = "nrtrans-encoded-examples/1"

Example = tuple[tuple[int, ...], tuple[int, ...]]  # (input ids, labels with the prompt masked as -100)


class ExamplesError(ValueError):
    """The file cannot be read, or was encoded for another base model, profile or prompt."""


@dataclass(frozen=True)
class EncodedExamples:
    examples: tuple[Example, ...]
    base_model_sha256: str
    profile_name: str
    profile_sha256: str
    prompt_version: int
    seed: int  # the seed the pairs were generated with
    pairs: int  # pairs generated, before those over the token budget were dropped
    groups: dict[str, int]
    normalized: tuple[str, ...]  # every generated task, so held-out pairs made later can avoid them
    transformers: str  # the version whose tokenizer encoded them, checked against llama.cpp's

    def write(self, path: Path) -> Path:
        partial = path.with_name(path.name + ".partial")
        with gzip.open(partial, "wt", encoding="utf-8") as handle:
            json.dump({"format": EXAMPLES_FORMAT, **asdict(self)}, handle)
        partial.replace(path)
        return path

    def check_fits(self, base_model_sha256: str, profile_sha256: str, prompt_version: int) -> None:
        """Refuse examples encoded for another base model, profile or prompt: they would teach the wrong
        tokens, skills or prompt layout."""
        for what, theirs, ours in (("base model", self.base_model_sha256, base_model_sha256),
                                   ("robot profile", self.profile_sha256, profile_sha256),
                                   ("prompt version", str(self.prompt_version), str(prompt_version))):
            if theirs != ours:
                raise ExamplesError(
                    f"these examples were encoded for another {what} ({theirs[:12]}, here {ours[:12]}).\n"
                    "  Encode them again with the same --profile and --model: "
                    "nrtrans train-adapter --save-examples FILE")


def read_examples(path: Path) -> EncodedExamples:
    try:
        with gzip.open(path, "rt", encoding="utf-8") as handle:
            data: dict[str, Any] = json.load(handle)
    except (OSError, EOFError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ExamplesError(f"cannot read encoded examples {path}: {exc}") from exc
    if not isinstance(data, dict) or data.pop("format", None) != EXAMPLES_FORMAT:
        raise ExamplesError(f"{path} is not a file of format {EXAMPLES_FORMAT}; write one with "
                            "nrtrans train-adapter --save-examples FILE")
    try:
        examples = tuple((tuple(ids), tuple(labels)) for ids, labels in data.pop("examples"))
        normalized = tuple(data.pop("normalized"))
        return EncodedExamples(examples=examples, normalized=normalized, **data)
    except (KeyError, TypeError, ValueError) as exc:
        raise ExamplesError(f"{path} is damaged or incomplete: {exc}") from exc
