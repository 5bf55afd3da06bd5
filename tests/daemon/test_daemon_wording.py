"""What the daemon and its clients say reads right: queue positions, poses, reset, the serve log."""

from __future__ import annotations

import io
import os
import subprocess
from pathlib import Path

import pytest

from agent.client import describe_event
from tests.daemon.conftest import NRTRANS, Daemon, follow


def test_queue_positions_and_poses_read_as_words() -> None:
    queued = {"event": "queued", "task": "t1", "position": 0}
    assert describe_event(queued) == "[t1] queued next in line"
    assert describe_event({**queued, "position": 1}) == "[t1] queued behind 1 other task"
    assert describe_event({**queued, "position": 3}) == "[t1] queued behind 3 other tasks"
    done = {"event": "done", "task": "t1", "state": {"pose": {"x": 1.0, "y": -0.0004, "heading": -0.001}}}
    assert describe_event(done) == "[t1] done pose x=1.00 y=0.00 heading=0.00"


def _nrtrans(daemon: Daemon, *args: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("NRTRANS_SOCKET", "NRTRANS_CONFIG")}
    return subprocess.run([NRTRANS, *args, "--socket", str(daemon.socket)], capture_output=True, text=True,
                          timeout=120, env=env)


def test_reset_the_serve_log_and_the_last_line(workdir: Path) -> None:
    daemon = Daemon(workdir).start()
    try:
        nothing = _nrtrans(daemon, "reset")
        assert nothing.returncode == 0, nothing.stderr
        assert nothing.stdout.startswith("no emergency stop was latched")
        assert _nrtrans(daemon, "estop", "--reason", "test").returncode == 0
        released = _nrtrans(daemon, "reset")
        assert released.stdout.startswith("emergency stop released (test)"), released.stdout
        with daemon.client() as client:
            for _ in range(2):
                task = client.submit(rsl="turnleft 0.1;", follow=True)
                assert follow(client, task)[-1]["event"] == "done"
    finally:
        assert daemon.stop() == 0
    log = daemon.output()
    assert log.count("ready:") == 1, log  # once when started, not again after every task
    assert "emergency stop released" in log
    assert log.rstrip().splitlines()[-1].endswith("stopped (exit status 0)"), log


def test_a_program_from_standard_input_is_called_so(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from agent.cli import main

    monkeypatch.setattr("sys.stdin", io.StringIO("forward 1;\n"))
    assert main(["check", "-"]) == 0
    assert capsys.readouterr().err.startswith("standard input: ok")
