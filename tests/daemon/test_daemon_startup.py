"""Startup failures: a clear error and a non-zero exit before READY=1."""

from __future__ import annotations

import subprocess
from pathlib import Path

from tests.daemon.conftest import NRTRANS, Daemon


def test_missing_model_fails_before_ready_with_a_clear_error(workdir: Path) -> None:
    daemon = Daemon(workdir, {"translator": {"model": str(workdir / "no-such-model.gguf")}})
    daemon.start(wait_ready=False)
    assert daemon.process is not None
    code = daemon.process.wait(120)
    assert code != 0
    assert daemon.notify is not None
    assert daemon.notify.wait_for("READY=1", 0.1) is None, "never READY without a model"
    output = daemon.output()
    assert "no-such-model.gguf" in output and "help:" in output, output
    assert "Traceback" not in output, output
    daemon.stop()
    assert not daemon.socket.exists(), "nothing listens when the daemon could not start"


def test_bad_config_is_reported_with_the_setting(workdir: Path) -> None:
    config = workdir / "bad.toml"
    config.write_text("[tasks]\nqueue_size = -1\n")
    result = subprocess.run([NRTRANS, "serve", "--config", str(config)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert "tasks.queue_size" in result.stderr and "Traceback" not in result.stderr


def test_missing_config_file_is_reported(workdir: Path) -> None:
    result = subprocess.run(
        [NRTRANS, "serve", "--config", str(workdir / "nope.toml")], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 2
    assert "cannot read config file" in result.stderr


def test_client_without_daemon_says_how_to_start_one(workdir: Path) -> None:
    result = subprocess.run(
        [NRTRANS, "send", "--socket", str(workdir / "none.sock"), "go forward"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 2
    assert "nrtrans serve" in result.stderr
