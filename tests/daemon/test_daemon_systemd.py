"""The systemd units: `systemd-analyze verify`, and the unit's ExecStart run by hand."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

import pytest

from agent.client import Client
from models.store import model_dir
from tests.daemon.conftest import NRTRANS, NotifyListener

UNITS = Path(__file__).resolve().parents[2] / "systemd"
INSTALLED_BINARY = "/usr/local/bin/nrtrans"


def _service_setting(name: str) -> str:
    for line in (UNITS / "nrtrans.service").read_text().splitlines():
        if line.startswith(f"{name}="):
            return line.split("=", 1)[1]
    raise AssertionError(f"nrtrans.service has no {name}=")


def _runnable_copy(directory: Path) -> None:
    """The units with ExecStart pointing at this checkout's nrtrans, and nothing else changed."""
    for unit in ("nrtrans.service", "nrtrans.socket"):
        text = (UNITS / unit).read_text()
        (directory / unit).write_text(text.replace(INSTALLED_BINARY, NRTRANS))


def test_units_pass_systemd_analyze_verify(tmp_path: Path) -> None:
    analyzer = shutil.which("systemd-analyze")
    if analyzer is None:
        pytest.skip("systemd-analyze is not installed (apt-get install systemd); scripts/test.sh installs it")
    _runnable_copy(tmp_path)
    result = subprocess.run(
        [analyzer, "verify", str(tmp_path / "nrtrans.service"), str(tmp_path / "nrtrans.socket")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "nrtrans.service" not in result.stderr, result.stderr


def test_unit_declares_what_the_issue_requires() -> None:
    text = (UNITS / "nrtrans.service").read_text()
    for line in (
        "Type=notify",
        "Restart=on-failure",
        "NoNewPrivileges=yes",
        "ProtectSystem=strict",
        "ProtectHome=yes",
        "PrivateTmp=yes",
        "StateDirectory=nrtrans",
        "RuntimeDirectory=nrtrans",
        "SupplementaryGroups=audio",
        "User=nrtrans",
    ):
        assert f"\n{line}\n" in text, line
    families = _service_setting("RestrictAddressFamilies").split()
    assert {"AF_UNIX", "AF_INET", "AF_INET6", "AF_NETLINK"} == set(families)
    assert int(_service_setting("WatchdogSec")) > 0


def test_execstart_reports_ready_pings_the_watchdog_and_stops_cleanly(workdir: Path) -> None:
    command = shlex.split(_service_setting("ExecStart"))
    assert command[0] == INSTALLED_BINARY
    command[0] = NRTRANS
    runtime, state = workdir / "run", workdir / "state"
    runtime.mkdir()
    state.mkdir()
    notify = NotifyListener(workdir / "notify")
    # What systemd puts in the environment for this unit (WatchdogSec shortened to keep the test quick).
    env = {
        **os.environ,
        "NOTIFY_SOCKET": str(workdir / "notify"),
        "WATCHDOG_USEC": "1000000",
        "RUNTIME_DIRECTORY": str(runtime),
        "STATE_DIRECTORY": str(state),
    }
    # A real install keeps its assembled model in the state directory across restarts; point at
    # the one already assembled on this machine rather than writing 250 MB per test run.
    env["NRTRANS_MODEL_DIR"] = str(model_dir())
    for key in ("NRTRANS_CONFIG", "WATCHDOG_PID", "LISTEN_FDS", "LISTEN_PID", "NRTRANS_SOCKET"):
        env.pop(key, None)
    log = open(workdir / "log", "wb")  # noqa: SIM115
    started = time.monotonic()
    process = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT)
    try:
        ready = notify.wait_for("READY=1", 180)
        assert ready is not None, (workdir / "log").read_text()
        assert (runtime / "nrtrans.sock").exists(), "the socket goes in $RUNTIME_DIRECTORY"
        assert oct((runtime / "nrtrans.sock").stat().st_mode & 0o777) == "0o660"
        second_ping = notify.wait_for("WATCHDOG=1", 10, count=2)
        assert second_ping is not None and second_ping > ready, "WATCHDOG=1 pings after READY=1"
        assert any(line.startswith("STATUS=") for line in notify.lines())
        process.send_signal(signal.SIGTERM)
        assert process.wait(60) == 0, (workdir / "log").read_text()
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        notify.close()
        log.close()
    assert "STOPPING=1" in notify.lines()
    assert not (runtime / "nrtrans.sock").exists(), "the socket file is removed on a clean stop"
    assert (state / "audit.jsonl").exists(), "the audit log goes in $STATE_DIRECTORY"
    print(f"start to READY=1: {ready - started:.2f} s")


def test_socket_activation_serves_on_the_inherited_socket(workdir: Path) -> None:
    """What nrtrans.socket does: systemd binds the socket and hands it over as fd 3."""
    path = workdir / "activated.sock"
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(str(path))
    listener.listen(16)
    config = workdir / "config.toml"
    config.write_text(f'state_dir = "{workdir / "state"}"\n[speech]\nenabled = false\n[translator]\nwarmup = false\n')
    notify = NotifyListener(workdir / "notify")
    env = {**os.environ, "NOTIFY_SOCKET": str(workdir / "notify"), "LISTEN_FDS": "1"}
    fd = listener.fileno()
    # systemd sets LISTEN_PID to the service's pid: the shell's, which exec keeps.
    command = ["/bin/sh", "-c", f'LISTEN_PID=$$ exec "{NRTRANS}" serve --config "{config}"']
    with open(workdir / "log", "wb") as log:
        # preexec_fn puts the listener at fd 3; listing 3 in pass_fds keeps it open across exec.
        process = subprocess.Popen(
            command, env=env, preexec_fn=lambda: os.dup2(fd, 3), pass_fds=(3, fd), stdout=subprocess.DEVNULL, stderr=log
        )
    listener.close()
    try:
        deadline = time.monotonic() + 180
        while notify.wait_for("READY=1", 0.5) is None:
            assert process.poll() is None and time.monotonic() < deadline, (workdir / "log").read_text()
        with Client.connect(path, timeout=30) as client:
            assert client.status()["state"] == "idle"
        process.send_signal(signal.SIGTERM)
        assert process.wait(60) == 0
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        notify.close()


def test_the_units_exposure_stays_low() -> None:
    """`systemd-analyze security` rates the unit; every remaining exposure is explained in its comments."""
    analyzer = shutil.which("systemd-analyze")
    if analyzer is None:
        pytest.skip("systemd-analyze is not installed (apt-get install systemd); scripts/test.sh installs it")
    result = subprocess.run(
        [analyzer, "security", "--offline=true", "--no-pager", str(UNITS / "nrtrans.service")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    match = re.search(r"Overall exposure level for nrtrans\.service: (\d+\.\d+)", result.stdout)
    assert match, result.stdout + result.stderr
    assert float(match.group(1)) <= 1.2, result.stdout
