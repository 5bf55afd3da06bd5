"""Fixtures for the adapter tests: the embedded base model and a llama.cpp loader."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def base_gguf() -> Path:
    from agent.translate.model_path import resolve_model

    return resolve_model(None)


def requires(*modules: str) -> None:
    """Skip with the reason when a module of the `train` extra is missing."""
    for module in modules:
        pytest.importorskip(module, reason=f"{module} is not installed: the adapter training tests need the "
                                           "train extra (pip install 'torch==2.13.0' 'nrtrans[train]')")
