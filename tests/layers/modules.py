"""Which source modules are runtime code and which are training code, for the layering tests."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# Modules only `nrtrans train-adapter` and the adapter benchmarks use: they may
# carry English templates about the default robot and import torch, and the
# daemon never imports them.
TRAINING_ONLY = frozenset({
    "agent.adapter.data",
    "agent.adapter.evaluate",
    "agent.adapter.export",
    "agent.adapter.hygiene",
    "agent.adapter.train",
})


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def runtime_modules() -> list[Path]:
    """Every module of agent/ and rsl/ except the training-only ones."""
    paths = sorted(p for package in ("agent", "rsl") for p in (ROOT / package).rglob("*.py"))
    return [p for p in paths if module_name(p) not in TRAINING_ONLY]
