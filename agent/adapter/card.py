"""The adapter card: a small JSON file beside the adapter saying what it is.

The runtime can check that an adapter was trained for the model and profile
it is about to use; people can see how it was made and how good it is.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

CARD_FORMAT = "nrtrans-adapter-card/1"
LICENCE = ("The adapter is a derivative of Gemma 3 270M and is distributed under the Gemma Terms of Use "
           "(https://ai.google.dev/gemma/terms) and its Prohibited Use Policy.")


@dataclass(frozen=True)
class AdapterCard:
    adapter_file: str
    adapter_sha256: str
    base_model_file: str
    base_model_sha256: str
    profile_name: str
    profile_sha256: str
    prompt_version: int
    data: dict[str, Any]
    training: dict[str, Any]
    eval: dict[str, Any] = field(default_factory=dict)
    licence: str = LICENCE
    format: str = CARD_FORMAT

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=2, sort_keys=True) + "\n"

    def write(self, path: Path) -> Path:
        partial = path.with_name(path.name + ".partial")
        partial.write_text(self.to_json(), encoding="utf-8")
        partial.replace(path)
        return path


def read_card(path: Path) -> AdapterCard:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise ValueError(f"cannot read adapter card {path}: {exc}") from exc
    if data.get("format") != CARD_FORMAT:
        raise ValueError(f"{path} is not an adapter card of format {CARD_FORMAT} (format: {data.get('format')!r})")
    return AdapterCard(**data)


def card_path(adapter: Path) -> Path:
    return adapter.with_suffix(".json")


def sha256_of(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
