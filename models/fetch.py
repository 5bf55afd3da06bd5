"""Download, resume, verify and unpack the models in the manifest.

Only `nrtrans models fetch` calls this; nothing downloads at run time. A
download goes into `FILE.part` and resumes from there with an HTTP Range
request, so an interrupted fetch of a 1.7 GB model does not start over. The
file gets its real name only once its sha256 matches the manifest.
"""

from __future__ import annotations

import http.client
import os
import shutil
import socket
import sys
import time
import urllib.error
import urllib.parse
import urllib.request
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from models.store import (
    VOSK_MARKERS,
    ModelEntry,
    ModelError,
    default_llm_path,
    directory_lock,
    installed_path,
    is_verified,
    model_dir,
    package_path,
    sha256_file,
    write_stamp,
    write_unpacked_stamp,
)

CHUNK = 256 * 1024
MB = 1024 * 1024


class FetchError(ModelError):
    """A download that did not complete; the message says what was kept."""


class OfflineError(FetchError):
    """The host cannot be reached at all."""


class ChecksumError(FetchError):
    """The bytes are not the ones the manifest pins."""


@dataclass(frozen=True)
class FetchResult:
    name: str
    path: Path
    sha256: str
    # False when the manifest pins no checksum: the caller must tell the user
    # to compare `sha256` with the publisher's.
    pinned: bool
    downloaded: int = 0
    resumed_from: int = 0
    already_present: bool = False


def fetch(entry: ModelEntry, *, url: str | None = None, sha256: str | None = None,
          directory: Path | None = None, progress: TextIO | None = sys.stderr,
          timeout: float = 30.0) -> FetchResult:
    """Make `entry` usable on this machine, downloading only what is missing."""
    expected = (sha256 or entry.sha256).lower()
    if entry.source == "python-package":
        path = default_llm_path(directory) if entry.kind == "llm" else package_path(entry)
        return FetchResult(entry.name, path, entry.sha256, bool(entry.sha256), already_present=True)
    base = directory or model_dir()
    target = installed_path(entry, base)
    if is_verified(entry, target) and not sha256:
        return FetchResult(entry.name, target, entry.sha256, bool(entry.sha256), already_present=True)
    with directory_lock(base):
        download_path = base / entry.file
        part = download_path.with_name(download_path.name + ".part")
        resumed_from = part.stat().st_size if part.exists() else 0
        downloaded = 0
        if not download_path.exists():
            downloaded = download(url or entry.url, part, name=entry.name, manual_path=download_path,
                                  expected_size=entry.size, progress=progress, timeout=timeout)
            actual = _check(part, expected, entry, delete_on_mismatch=True)
            os.replace(part, download_path)
        else:
            actual = _check(download_path, expected, entry, delete_on_mismatch=False)
        _install(entry, download_path, target, actual)
    return FetchResult(entry.name, target, actual, bool(expected), downloaded=downloaded,
                       resumed_from=resumed_from)


def verify(entry: ModelEntry, *, sha256: str | None = None, directory: Path | None = None) -> FetchResult:
    """Check (and for archives, unpack) a model that was fetched or copied in by hand."""
    expected = (sha256 or entry.sha256).lower()
    if entry.source == "python-package":
        path = default_llm_path(directory) if entry.kind == "llm" else package_path(entry)
        if entry.kind == "llm":
            return FetchResult(entry.name, path, sha256_file(path), True)
        return FetchResult(entry.name, path, "", False, already_present=True)
    base = directory or model_dir()
    target = installed_path(entry, base)
    download_path = base / entry.file
    with directory_lock(base):
        if entry.archive and not download_path.exists() and is_verified(entry, target):
            _require_markers(entry, target)
            return FetchResult(entry.name, target, entry.sha256, bool(entry.sha256), already_present=True)
        if not download_path.exists():
            raise ModelError(f"model `{entry.name}` is not in {base}: there is no {entry.file}. "
                             f"Run `nrtrans models fetch {entry.name}`, or copy {entry.file} from "
                             f"{entry.url} into {base} and run this again.")
        actual = _check(download_path, expected, entry, delete_on_mismatch=False)
        _install(entry, download_path, target, actual)
    return FetchResult(entry.name, target, actual, bool(expected), already_present=True)


def download(url: str, part: Path, *, name: str, manual_path: Path, expected_size: int = 0,
             progress: TextIO | None = sys.stderr, timeout: float = 30.0) -> int:
    """Append the rest of `url` to `part`, resuming where it stopped; returns the bytes received."""
    part.parent.mkdir(parents=True, exist_ok=True)
    have = part.stat().st_size if part.exists() else 0
    host = urllib.parse.urlsplit(url).hostname or url
    request = urllib.request.Request(url, headers={"User-Agent": "nrtrans-models/1"})
    token = os.environ.get("HF_TOKEN")
    if token and host.endswith("huggingface.co"):
        request.add_header("Authorization", f"Bearer {token}")
    if have:
        request.add_header("Range", f"bytes={have}-")
    try:
        response = urllib.request.urlopen(request, timeout=timeout)
    except urllib.error.HTTPError as exc:
        if exc.code == 416 and have:
            # The server has nothing past what we hold: the part is complete
            # (or stale, which the checksum will catch).
            return 0
        raise FetchError(_http_message(exc.code, host, name, url)) from None
    except (urllib.error.URLError, OSError) as exc:
        raise OfflineError(_offline_message(exc, host, name, manual_path)) from None
    with response:
        resumed = have > 0 and response.status == 206
        start = have if resumed else 0
        length = response.headers.get("Content-Length")
        total = start + int(length) if length and length.isdigit() else expected_size
        meter = Progress(progress, part.name.removesuffix(".part"), total, start)
        received = 0
        try:
            with part.open("ab" if resumed else "wb") as out:
                while block := response.read(CHUNK):
                    out.write(block)
                    received += len(block)
                    meter.update(start + received)
                out.flush()
                os.fsync(out.fileno())
        except (OSError, http.client.HTTPException) as exc:
            meter.close()
            raise FetchError(_interrupted_message(start + received, part, name, f"{exc}")) from None
        except KeyboardInterrupt:
            meter.close()
            print(_interrupted_message(part.stat().st_size, part, name, "interrupted"), file=sys.stderr)
            raise
        meter.close()
    if total and start + received < total:
        raise FetchError(_interrupted_message(start + received, part, name,
                                              f"the server closed the connection at "
                                              f"{(start + received) / MB:.1f} of {total / MB:.1f} MB"))
    return received


class Progress:
    """A one-line progress bar on stderr: percent, size, rate and time left."""

    def __init__(self, stream: TextIO | None, label: str, total: int, start: int) -> None:
        self.stream = stream
        self.label = label
        self.total = total
        self.start = start
        self.done = start
        self.began = time.monotonic()
        self.shown = 0.0
        self.tty = bool(stream is not None and stream.isatty())
        # A log file gets a line every few seconds rather than a redraw.
        self.every = 0.2 if self.tty else 5.0

    def update(self, done: int) -> None:
        self.done = done
        now = time.monotonic()
        if self.stream is not None and now - self.shown >= self.every:
            self.shown = now
            self._draw(now, final=False)

    def close(self) -> None:
        if self.stream is not None:
            self._draw(time.monotonic(), final=True)

    def _draw(self, now: float, final: bool) -> None:
        assert self.stream is not None
        elapsed = max(now - self.began, 1e-6)
        rate = (self.done - self.start) / elapsed
        if self.total:
            fraction = min(self.done / self.total, 1.0)
            left = (self.total - self.done) / rate if rate > 0 else 0.0
            bar = "#" * int(fraction * 24)
            text = (f"{self.label} [{bar:<24}] {fraction:4.0%} {self.done / MB:.1f}/{self.total / MB:.1f} MB "
                    f"{rate / MB:.1f} MB/s, {_duration(left)} left")
        else:
            text = f"{self.label} {self.done / MB:.1f} MB {rate / MB:.1f} MB/s"
        if self.tty:
            self.stream.write("\r" + text + ("\n" if final else ""))
        else:
            self.stream.write(text + "\n")
        self.stream.flush()


def _duration(seconds: float) -> str:
    seconds = int(seconds)
    return f"{seconds // 60}m{seconds % 60:02d}s" if seconds >= 60 else f"{seconds}s"


def _check(path: Path, expected: str, entry: ModelEntry, delete_on_mismatch: bool) -> str:
    actual = sha256_file(path)
    if entry.size and path.stat().st_size != entry.size and expected and actual != expected:
        size_note = f" It has {path.stat().st_size} bytes where {entry.size} were expected."
    else:
        size_note = ""
    if expected and actual != expected:
        if delete_on_mismatch:
            path.unlink(missing_ok=True)
            fate = ("The download was deleted, since resuming would keep the bad bytes. Run the fetch "
                    "again; if it fails the same way, the mirror serves a different file than the manifest "
                    "pins (check the url, or pass --sha256 if the publisher changed the file).")
        else:
            fate = (f"The file was left in place. Delete it and run `nrtrans models fetch {entry.name}`, "
                    "or copy in the right file.")
        raise ChecksumError(f"checksum mismatch for `{entry.name}` ({path}): sha256 is {actual}, but "
                            f"{expected} was expected.{size_note} {fate}")
    return actual


def _install(entry: ModelEntry, download_path: Path, target: Path, sha256: str) -> None:
    override = bool(entry.sha256) and sha256 != entry.sha256
    if not entry.archive:
        write_stamp(download_path, sha256, override)
        return
    temp = target.parent / f".unpack-{entry.name}-{os.getpid()}"
    shutil.rmtree(temp, ignore_errors=True)
    try:
        root = _unzip(download_path, temp, entry)
        _require_markers(entry, root)
        if target.exists():
            shutil.rmtree(target)
        os.replace(root, target)
        write_unpacked_stamp(target, sha256, override)
    finally:
        shutil.rmtree(temp, ignore_errors=True)
    # The archive is only a carrier; the unpacked, stamped directory is the model.
    download_path.unlink(missing_ok=True)


def _unzip(archive: Path, into: Path, entry: ModelEntry) -> Path:
    try:
        with zipfile.ZipFile(archive) as bundle:
            into.mkdir(parents=True)
            for member in bundle.infolist():
                destination = (into / member.filename).resolve()
                if not destination.is_relative_to(into.resolve()):
                    raise ModelError(f"{archive}: refusing to unpack `{member.filename}`, which points "
                                     "outside the model directory")
            bundle.extractall(into)
    except zipfile.BadZipFile:
        raise ModelError(f"{archive} is not a zip archive, though `{entry.name}` should be one. "
                         f"Delete it and run `nrtrans models fetch {entry.name}`.") from None
    children = [c for c in into.iterdir() if not c.name.startswith("__MACOSX")]
    # Vosk archives hold one top-level folder named after the model.
    return children[0] if len(children) == 1 and children[0].is_dir() else into


def _require_markers(entry: ModelEntry, directory: Path) -> None:
    if entry.kind != "vosk":
        return
    missing = [m for m in VOSK_MARKERS if not (directory / m).is_dir()]
    if missing:
        raise ModelError(f"`{entry.name}` unpacked into {directory} has no {' or '.join(missing)}/ "
                         "directory, so it is not a Vosk model. The archive is wrong; delete it and "
                         "fetch again.")


def _offline_message(exc: BaseException, host: str, name: str, manual_path: Path) -> str:
    reason = exc.reason if isinstance(exc, urllib.error.URLError) else exc
    if isinstance(reason, socket.gaierror):
        why = "its name does not resolve"
    elif isinstance(reason, ConnectionRefusedError):
        why = "the connection was refused"
    elif isinstance(reason, TimeoutError | socket.timeout):
        why = "the connection timed out"
    else:
        why = str(reason)
    return (f"cannot reach {host} ({why}): this machine looks offline. Copy {manual_path.name} to "
            f"{manual_path} from a machine that has it, then run `nrtrans models verify {name}`.")


def _http_message(code: int, host: str, name: str, url: str) -> str:
    if code in (401, 403):
        return (f"{host} refused the download of `{name}` (HTTP {code}). Gated models such as Gemma need you "
                f"to accept the licence on the model page and to set HF_TOKEN to an access token. URL: {url}")
    if code == 404:
        return (f"{host} has no file at {url} (HTTP 404). The manifest's url is out of date; pass a "
                f"working one with `nrtrans models fetch {name} --url URL`.")
    return f"{host} answered HTTP {code} for {url}. Try again later, or use a mirror with --url."


def _interrupted_message(have: int, part: Path, name: str, why: str) -> str:
    return (f"the download of `{name}` stopped ({why}). The {have / MB:.1f} MB received are kept in {part}; "
            f"run `nrtrans models fetch {name}` again to resume from there.")
