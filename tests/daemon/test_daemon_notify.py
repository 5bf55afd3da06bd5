"""sd_notify over a real datagram socket, path and abstract namespace."""

from __future__ import annotations

import os
import socket
import uuid
from pathlib import Path

import pytest

from agent.daemon.notify import Notifier, watchdog_interval


def _receiver(address: str) -> socket.socket:
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind("\0" + address[1:] if address.startswith("@") else address)
    sock.settimeout(2.0)
    return sock


@pytest.mark.parametrize("abstract", [False, True])
def test_ready_status_and_watchdog_arrive(tmp_path: Path, abstract: bool) -> None:
    address = f"@nrtrans-test-{uuid.uuid4().hex}" if abstract else str(tmp_path / "notify")
    receiver = _receiver(address)
    notifier = Notifier(address)
    try:
        assert notifier.ready("serving")
        lines = receiver.recv(4096).decode().split("\n")
        assert "READY=1" in lines and "STATUS=serving" in lines and f"MAINPID={os.getpid()}" in lines
        assert notifier.watchdog()
        assert receiver.recv(4096) == b"WATCHDOG=1"
    finally:
        notifier.close()
        receiver.close()


def test_no_manager_is_not_an_error(tmp_path: Path) -> None:
    assert not Notifier("").send("READY=1")
    # A manager that went away must not crash the daemon.
    assert not Notifier(str(tmp_path / "gone")).send("READY=1")


def test_watchdog_interval_is_half_the_timeout(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("WATCHDOG_USEC", "3000000")
    monkeypatch.delenv("WATCHDOG_PID", raising=False)
    assert watchdog_interval() == 1.5
    monkeypatch.setenv("WATCHDOG_PID", str(os.getpid() + 1))
    assert watchdog_interval() is None
    monkeypatch.setenv("WATCHDOG_USEC", "0")
    monkeypatch.delenv("WATCHDOG_PID")
    assert watchdog_interval() is None
