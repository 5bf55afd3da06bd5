"""End to end: a spoken-style task over the socket, the embedded model, the simulator."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.daemon.conftest import Daemon, follow


@pytest.fixture
def daemon(workdir: Path) -> Iterator[Daemon]:
    running = Daemon(workdir, {"robot": {"realtime_factor": 0.0}, "translator": {"warmup": True}}).start()
    yield running
    assert running.stop() == 0, running.output()


def test_move_forward_one_meter_then_turn_left(daemon: Daemon) -> None:
    with daemon.client(timeout=300) as client:
        task = client.submit(text="move forward one meter then turn left", follow=True)
        events = follow(client, task)
        record = client.status(task)
    names = [e["event"] for e in events]
    assert names[:2] == ["queued", "translating"], names
    assert "attempt" in names and "verified" in names, names
    assert names[-1] == "done", (names, events[-1])
    verified = next(e for e in events if e["event"] == "verified")
    pose = events[-1]["state"]["pose"]
    assert pose["x"] == pytest.approx(1.0, abs=0.05), verified["program"]
    assert pose["y"] == pytest.approx(0.0, abs=0.05), verified["program"]
    assert math.remainder(pose["heading"] - math.pi / 2, math.tau) == pytest.approx(0.0, abs=0.05), verified["program"]
    assert record["attempts"] and record["model"]
    assert record["timings_ms"]["first_command_ms"] > 0
