"""The audit log: an append-only JSONL journal of every task, fsync'd as it goes.

Each line is a full snapshot of one task's record so far (`rev` counts them
and `final` marks the last), so the record of a task is simply its last
line, and a crash at any moment leaves every earlier line intact. Lines are
written before the robot moves and after each step.

A task whose last line is not final when the daemon starts was in flight
during a crash: it gets a final `interrupted` line and is never run again.
Rotation happens only when no task is open, so one task's lines always sit
in one file and recovery reads only the current file.
"""

from __future__ import annotations

import json
import logging
import os
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

log = logging.getLogger(__name__)

FORMAT = 1
INTERRUPTED_REASON = (
    "the daemon stopped while this task was in flight (crash, kill or power loss); it was not run again"
)


class AuditError(OSError):
    """The audit log cannot be opened or written; nothing may move without it."""


class AuditLog:
    def __init__(self, path: Path, *, max_bytes: int = 10_000_000, keep: int = 5) -> None:
        self.path = path
        self.max_bytes = max_bytes
        self.keep = keep
        self._lock = threading.Lock()
        self._file: Any = None
        self._revs: dict[str, int] = {}
        self._open_tasks: set[str] = set()

    def open(self) -> list[dict[str, Any]]:
        """Open for appending and close out tasks a crash left open; returns their records."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True, mode=0o750)
            self._file = open(self.path, "ab")  # noqa: SIM115 - kept open for the daemon's life
        except OSError as exc:
            raise AuditError(
                exc.errno,
                f"cannot open the audit log {self.path}: {exc.strerror}\n"
                "  = help: make the state directory writable, or set --state-dir",
            ) from exc
        last: dict[str, dict[str, Any]] = {}
        for record in read_records(self.path):
            last[record["task"]] = record
            self._revs[record["task"]] = int(record.get("rev", 0))
        if self._file.tell() > 0 and not _ends_with_newline(self.path):
            # A torn line from a crash mid-write: end it so the next record starts clean.
            self._write_bytes(b"\n")
        interrupted = []
        for record in last.values():
            if record.get("final"):
                continue
            closed = {**record, "state": "interrupted", "reason": INTERRUPTED_REASON, "interrupted_at": time.time()}
            self.write(closed, final=True)
            interrupted.append(closed)
        return interrupted

    def write(self, record: dict[str, Any], *, final: bool = False) -> None:
        """Append one snapshot of `record` (which has a "task" id) and fsync it."""
        task_id = record["task"]
        with self._lock:
            if task_id not in self._open_tasks and not final:
                self._rotate_if_due()
                self._open_tasks.add(task_id)
            rev = self._revs.get(task_id, 0) + 1
            self._revs[task_id] = rev
            line = {**record, "audit": FORMAT, "rev": rev, "final": final, "written": time.time()}
            self._write_bytes(json.dumps(line, ensure_ascii=False, default=str).encode("utf-8") + b"\n")
            if final:
                self._open_tasks.discard(task_id)
                self._revs.pop(task_id, None)

    def recent(self, limit: int) -> list[dict[str, Any]]:
        """The last `limit` task records, oldest first, across rotated files."""
        found: dict[str, dict[str, Any]] = {}
        for path in self._files_newest_first():
            in_file: dict[str, dict[str, Any]] = {}
            for record in read_records(path):
                in_file[record["task"]] = record
            for task_id, record in reversed(in_file.items()):
                found.setdefault(task_id, record)
            if len(found) >= limit:
                break
        newest_first = list(found.values())[:limit]
        return sorted(newest_first, key=lambda r: r.get("created", 0.0))

    def close(self) -> None:
        with self._lock:
            if self._file is not None:
                self._file.close()
                self._file = None

    def _write_bytes(self, data: bytes) -> None:
        if self._file is None:
            raise AuditError(0, f"the audit log {self.path} is not open")
        try:
            self._file.write(data)
            self._file.flush()
            os.fsync(self._file.fileno())
        except OSError as exc:
            raise AuditError(exc.errno, f"cannot write the audit log {self.path}: {exc.strerror}") from exc

    def _rotate_if_due(self) -> None:
        if self._open_tasks or self._file is None or self._file.tell() < self.max_bytes:
            return
        self._file.close()
        for index in range(self.keep, 0, -1):
            older = self._rotated(index)
            newer = self._rotated(index - 1) if index > 1 else self.path
            if index == self.keep and older.exists():
                older.unlink()
            if newer.exists():
                newer.rename(older)
        if self.keep == 0:
            self.path.unlink(missing_ok=True)
        self._file = open(self.path, "ab")  # noqa: SIM115
        _fsync_dir(self.path.parent)
        log.info("rotated the audit log %s", self.path)

    def _rotated(self, index: int) -> Path:
        return self.path.with_name(f"{self.path.name}.{index}")

    def _files_newest_first(self) -> Iterator[Path]:
        if self.path.exists():
            yield self.path
        for index in range(1, self.keep + 1):
            rotated = self._rotated(index)
            if rotated.exists():
                yield rotated


def read_records(path: Path) -> Iterator[dict[str, Any]]:
    """Every well-formed record line in one file; a torn or foreign line is skipped, not fatal."""
    try:
        handle = open(path, "rb")  # noqa: SIM115
    except FileNotFoundError:
        return
    with handle:
        for number, raw in enumerate(handle, 1):
            try:
                record = json.loads(raw)
            except ValueError:
                log.warning("%s:%d: skipping a line that is not JSON (torn by a crash?)", path, number)
                continue
            if isinstance(record, dict) and isinstance(record.get("task"), str):
                yield record


def _ends_with_newline(path: Path) -> bool:
    with open(path, "rb") as handle:
        handle.seek(-1, os.SEEK_END)
        return handle.read(1) == b"\n"


def _fsync_dir(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
