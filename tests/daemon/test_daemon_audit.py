"""The audit log: fsync'd snapshots, crash recovery without replay, rotation."""

from __future__ import annotations

import json
from pathlib import Path

from agent.daemon.audit import AuditLog, read_records


def _lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def test_each_change_is_a_full_snapshot_and_the_last_is_final(tmp_path: Path) -> None:
    log = AuditLog(tmp_path / "audit.jsonl")
    assert log.open() == []
    log.write({"task": "a", "state": "queued", "created": 1.0})
    log.write({"task": "a", "state": "executing", "created": 1.0, "steps": []})
    log.write({"task": "a", "state": "done", "created": 1.0, "steps": [{"step": 1}]}, final=True)
    log.close()
    lines = _lines(tmp_path / "audit.jsonl")
    assert [(r["rev"], r["state"], r["final"]) for r in lines] == [
        (1, "queued", False),
        (2, "executing", False),
        (3, "done", True),
    ]
    assert AuditLog(tmp_path / "audit.jsonl").recent(5)[0]["state"] == "done"


def test_a_task_open_at_a_crash_is_marked_interrupted_once(tmp_path: Path) -> None:
    path = tmp_path / "audit.jsonl"
    log = AuditLog(path)
    log.open()
    log.write({"task": "done1", "state": "done", "created": 1.0}, final=True)
    log.write({"task": "moving", "state": "executing", "created": 2.0, "plan": [{"skill": "forward"}]})
    log.close()
    # A crash also tears the line being written.
    with open(path, "ab") as handle:
        handle.write(b'{"task": "torn", "sta')

    restarted = AuditLog(path)
    interrupted = restarted.open()
    assert [r["task"] for r in interrupted] == ["moving"]
    restarted.write({"task": "next", "state": "queued", "created": 3.0})
    restarted.close()

    records = {r["task"]: r for r in read_records(path)}
    assert records["moving"]["state"] == "interrupted" and records["moving"]["final"]
    assert records["moving"]["plan"] == [{"skill": "forward"}], "the interrupted record keeps its plan"
    assert records["next"]["state"] == "queued", "a record after the torn line is readable"
    again = AuditLog(path)
    assert [r["task"] for r in again.open()] == ["next"], "only the task queued after the restart"
    again.close()
    assert AuditLog(path).open() == [], "a third start finds nothing left to interrupt"


def test_rotation_happens_between_tasks_only(tmp_path: Path) -> None:
    path = tmp_path / "audit.jsonl"
    log = AuditLog(path, max_bytes=1024, keep=2)
    log.open()
    padding = "x" * 100
    for index in range(12):
        task = f"t{index}"
        log.write({"task": task, "state": "queued", "created": float(index), "pad": padding})
        log.write({"task": task, "state": "executing", "created": float(index), "pad": padding})
        log.write({"task": task, "state": "done", "created": float(index), "pad": padding}, final=True)
    log.close()
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == ["audit.jsonl", "audit.jsonl.1", "audit.jsonl.2"]
    for name in files:
        per_task: dict[str, list[int]] = {}
        for record in read_records(tmp_path / name):
            per_task.setdefault(record["task"], []).append(record["rev"])
        assert all(revs == [1, 2, 3] for revs in per_task.values()), f"a task was split in {name}"
    recent = AuditLog(path, keep=2).recent(4)
    assert [r["task"] for r in recent] == ["t8", "t9", "t10", "t11"]
