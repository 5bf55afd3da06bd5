"""A real `nrtrans serve` process per test module, with a notify socket the test owns."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from agent.client import Client
from agent.daemon.schemas import ERROR, EVENT, REPLY

NRTRANS = str(Path(sys.executable).with_name("nrtrans"))
VALIDATORS = {
    "reply": Draft202012Validator(REPLY),
    "error": Draft202012Validator(ERROR),
    "event": Draft202012Validator(EVENT),
}


def check_frame(frame: dict[str, Any]) -> dict[str, Any]:
    """Every frame the daemon sends must match its published schema."""
    VALIDATORS[frame["type"]].validate(frame)
    return frame


class NotifyListener:
    """The datagram socket systemd would own: records every sd_notify message with its time."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.messages: list[tuple[float, str]] = []
        self._cond = threading.Condition()
        self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self._sock.bind(str(path))
        self._sock.settimeout(0.2)
        self._closed = False
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._closed:
            try:
                data = self._sock.recv(65536)
            except TimeoutError:
                continue
            except OSError:
                return
            with self._cond:
                self.messages.append((time.monotonic(), data.decode()))
                self._cond.notify_all()

    def lines(self) -> list[str]:
        with self._cond:
            return [line for _t, message in self.messages for line in message.split("\n")]

    def wait_for(self, line: str, timeout: float, count: int = 1) -> float | None:
        """Monotonic time at which `line` had arrived `count` times, or None."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                hits = [t for t, message in self.messages if line in message.split("\n")]
                if len(hits) >= count:
                    return hits[count - 1]
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self._cond.wait(remaining)

    def close(self) -> None:
        self._closed = True
        self._sock.close()


def _toml(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"
    return repr(value)


class Daemon:
    """`nrtrans serve` in a subprocess; `settings` are config sections, e.g. {"tasks": {"queue_size": 2}}."""

    def __init__(
        self,
        workdir: Path,
        settings: dict[str, dict[str, Any]] | None = None,
        *,
        extra_env: dict[str, str] | None = None,
    ) -> None:
        self.workdir = workdir
        self.socket = workdir / "api.sock"
        self.state_dir = workdir / "state"
        self.config_file = workdir / "config.toml"
        self.log = workdir / "daemon.log"
        sections: dict[str, dict[str, Any]] = {
            "api": {"socket": str(self.socket)},
            "robot": {"realtime_factor": 1.0},
            "speech": {"enabled": False},
            # Only the end-to-end test needs the model warm; the others leave the CPU to the tests.
            "translator": {"warmup": False},
        }
        for name, values in (settings or {}).items():
            sections.setdefault(name, {}).update(values)
        text = f"state_dir = {_toml(str(self.state_dir))}\n"
        for name, values in sections.items():
            text += f"\n[{name}]\n" + "".join(f"{k} = {_toml(v)}\n" for k, v in values.items())
        self.config_file.write_text(text, encoding="utf-8")
        self.extra_env = extra_env or {}
        self.process: subprocess.Popen[bytes] | None = None
        self.notify: NotifyListener | None = None
        self.started_at = 0.0

    def start(self, *, wait_ready: bool = True, timeout: float = 180.0) -> Daemon:
        notify_path = self.workdir / f"notify-{time.monotonic_ns()}"
        self.notify = NotifyListener(notify_path)
        env = {**os.environ, "NOTIFY_SOCKET": str(notify_path), **self.extra_env}
        env.pop("NRTRANS_CONFIG", None)
        self.started_at = time.monotonic()
        with open(self.log, "ab") as log:
            self.process = subprocess.Popen(
                [NRTRANS, "serve", "--config", str(self.config_file)], stdout=log, stderr=subprocess.STDOUT, env=env
            )
        if wait_ready:
            deadline = time.monotonic() + timeout
            while self.notify.wait_for("READY=1", 0.5) is None:
                if self.process.poll() is not None or time.monotonic() > deadline:
                    raise AssertionError(f"the daemon did not become ready:\n{self.output()}")
        return self

    def output(self) -> str:
        return self.log.read_text(errors="replace") if self.log.exists() else ""

    def client(self, timeout: float = 60.0) -> Client:
        return Client.connect(self.socket, timeout=timeout)

    def send_signal(self, sig: int) -> None:
        assert self.process is not None
        self.process.send_signal(sig)

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 60.0) -> int:
        assert self.process is not None
        if self.process.poll() is None:
            self.process.send_signal(sig)
        try:
            code = self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            code = self.process.wait()
        if self.notify is not None:
            self.notify.close()
        return code


@pytest.fixture
def workdir() -> Iterator[Path]:
    # Unix socket paths are limited to 107 bytes, so not under pytest's long tmp_path.
    path = Path(tempfile.mkdtemp(prefix="nrd-", dir="/tmp"))
    os.chmod(path, 0o755)
    yield path
    shutil.rmtree(path, ignore_errors=True)


@pytest.fixture(scope="module")
def module_workdir() -> Iterator[Path]:
    path = Path(tempfile.mkdtemp(prefix="nrd-", dir="/tmp"))
    os.chmod(path, 0o755)
    yield path
    shutil.rmtree(path, ignore_errors=True)


def settle(daemon: Daemon, timeout_s: float) -> None:
    """Release any latched emergency stop and wait until the robot is idle, so the next test starts clean."""
    with daemon.client() as client:
        client.reset()
        deadline = time.monotonic() + timeout_s
        while client.status()["state"] != "idle" and time.monotonic() < deadline:
            time.sleep(0.1)


def follow(client: Client, task: str, timeout: float = 300.0) -> list[dict[str, Any]]:
    """A followed task's events up to its terminal one, each checked against the schema."""
    client.settimeout(timeout)
    return [check_frame(event) for event in client.follow(task)]
