"""Asking before moving, through a real daemon: an unsure plan waits for `confirm` and moves only when accepted."""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from agent.client import Client, RequestFailed
from tests.daemon.conftest import Daemon, check_frame, follow

TIMEOUT_S = 3.0
# Whatever the model writes for it, a plan for "pick it up" names an object nobody said, or does not
# use the gripper that was asked for: the meaning checks doubt it, so the daemon asks.
UNSURE = "pick it up"
NOT_A_TASK = "thank you, that is all for today"


@pytest.fixture(scope="module")
def daemon(module_workdir: Path) -> Iterator[Daemon]:
    running = Daemon(module_workdir, {"translator": {"adapter": "default", "confirm": "unsure",
                                                     "confirm_timeout": TIMEOUT_S}}).start()
    yield running
    assert running.stop() == 0, running.output()


@pytest.fixture(autouse=True)
def released(daemon: Daemon) -> Iterator[None]:
    yield
    with daemon.client() as client:
        client.reset()


def _pose(client: Client) -> dict[str, float]:
    return dict(client.health()["components"]["robot"]["state"]["pose"])


def _until(client: Client, task: str, name: str) -> list[dict[str, Any]]:
    """The task's events up to and including the first `name` one."""
    client.settimeout(300)
    seen = []
    for event in client.follow(task):
        seen.append(check_frame(event))
        if event["event"] == name:
            return seen
    raise AssertionError(f"the task ended without a {name!r} event: {[e['event'] for e in seen]}")


def _asked(client: Client) -> tuple[str, dict[str, Any], dict[str, float]]:
    before = _pose(client)
    task = client.submit(text=UNSURE, follow=True)
    events = _until(client, task, "confirm")
    verified = next(e for e in events if e["event"] == "verified")
    question = events[-1]
    assert question["explanation"] == verified["explanation"] and question["explanation"]
    assert question["confidence"] is not None and question["confidence"] < 0.5 and question["reasons"]
    assert question["timeout_s"] == TIMEOUT_S and question["text"] == UNSURE
    assert client.status(task)["state"] == "confirming"
    return task, question, before


def test_an_unsure_task_waits_for_confirm_then_runs(daemon: Daemon) -> None:
    with daemon.client() as client:
        task, _question, _before = _asked(client)
        time.sleep(TIMEOUT_S / 2)
        assert client.status(task)["state"] == "confirming", "it must not run before the answer"
        reply = client.confirm(task, True)
        assert reply["accepted"] is True
        events = follow(client, task)
    names = [e["event"] for e in events]
    assert names[0] == "answered" and events[0]["by"] == f"uid {os.getuid()}" and events[0]["accepted"]
    assert "executing" in names, names
    with daemon.client() as client:
        record = client.status(task)
        assert record["confirmed_by"] == f"uid {os.getuid()}"
        assert any(r["task"] == task and r["confirmed_by"] == f"uid {os.getuid()}" for r in client.history(50))


def test_a_declined_task_never_moves(daemon: Daemon) -> None:
    with daemon.client() as client:
        task, _question, before = _asked(client)
        client.confirm(task, False)
        events = follow(client, task)
        assert [e["event"] for e in events] == ["answered", "cancelled"]
        assert "declined by uid" in events[-1]["reason"]
        assert _pose(client) == before
        with pytest.raises(RequestFailed) as answered:
            client.confirm(task, True)
        assert answered.value.code == "not_waiting"


def test_an_unanswered_task_times_out_and_never_moves(daemon: Daemon) -> None:
    with daemon.client() as client:
        task, _question, before = _asked(client)
        events = follow(client, task)
        assert [e["event"] for e in events] == ["cancelled"]
        assert f"no answer within {TIMEOUT_S:g} s" in events[-1]["reason"]
        assert _pose(client) == before


def test_an_estop_while_waiting_ends_the_task(daemon: Daemon) -> None:
    with daemon.client() as client:
        task, _question, before = _asked(client)
        with daemon.client() as other:
            other.estop("test")
        events = follow(client, task)
        assert events[-1]["event"] == "cancelled" and "emergency stop" in events[-1]["reason"]
        assert _pose(client) == before


def test_a_non_task_through_the_socket_does_not_move_the_robot(daemon: Daemon) -> None:
    with daemon.client() as client:
        before = _pose(client)
        task = client.submit(text=NOT_A_TASK, follow=True)
        events = follow(client, task)
        names = [e["event"] for e in events]
        assert names[-1] == "rejected" and "executing" not in names, names
        assert "not understood as a task" in events[-1]["reason"] and "drive" in events[-1]["reason"]
        assert _pose(client) == before
