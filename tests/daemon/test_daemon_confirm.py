"""Asking before moving, through a real daemon: an unsure plan waits for `confirm` and moves only when accepted."""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from agent.client import Client, RequestFailed
from agent.translate.confidence import UNSURE_BELOW
from tests.daemon.conftest import Daemon, check_frame, follow

TIMEOUT_S = 3.0
TASK = "drive forward 0.3 meters"
# Speech-recognizer noise for "turn right four times": the shipped adapter writes four quarter turns, but
# is only about 31 % sure of its words (2026-11-27), so the default policy asks; if a retrained adapter
# is sure of it, pick another phrase it is unsure of (the test below checks it is unsure).
UNSURE = "turn right for times"
NOT_A_TASK = "thank you, that is all for today"


def _settings(policy: str) -> dict[str, dict[str, Any]]:
    return {"translator": {"adapter": "default", "confirm": policy, "confirm_timeout": TIMEOUT_S},
            "robot": {"realtime_factor": 0.0}}


@pytest.fixture(scope="module")
def daemon(module_workdir: Path) -> Iterator[Daemon]:
    # "always" asks whatever the model writes, so the waiting itself is tested apart from the model.
    running = Daemon(module_workdir, _settings("always")).start()
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


def _asked(client: Client, text: str = TASK) -> tuple[str, dict[str, Any], dict[str, float]]:
    before = _pose(client)
    task = client.submit(text=text, follow=True)
    events = _until(client, task, "confirm")
    verified = next(e for e in events if e["event"] == "verified")
    question = events[-1]
    assert question["explanation"] == verified["explanation"] and question["explanation"]
    assert question["timeout_s"] == TIMEOUT_S and question["text"] == text
    assert client.status(task)["state"] == "confirming"
    return task, question, before


def _accepted_and_run(client: Client, task: str, before: dict[str, float]) -> None:
    time.sleep(TIMEOUT_S / 2)
    assert client.status(task)["state"] == "confirming", "it must not run before the answer"
    assert _pose(client) == before
    reply = client.confirm(task, True)
    assert reply["accepted"] is True
    events = follow(client, task)
    names = [e["event"] for e in events]
    assert names[0] == "answered" and events[0]["by"] == f"uid {os.getuid()}" and events[0]["accepted"]
    assert "executing" in names and names[-1] == "done", names
    assert _pose(client) != before
    record = client.status(task)
    assert record["confirmed_by"] == f"uid {os.getuid()}"
    assert any(r["task"] == task and r["confirmed_by"] == f"uid {os.getuid()}" for r in client.history(50))


def test_a_task_waits_for_confirm_then_runs(daemon: Daemon) -> None:
    with daemon.client() as client:
        task, question, before = _asked(client)
        assert question["explanation"] == "drive forward 30 cm"
        _accepted_and_run(client, task, before)


def test_under_the_default_policy_only_an_unsure_task_waits(daemon: Daemon) -> None:
    text = daemon.config_file.read_text(encoding="utf-8").replace('confirm = "always"', 'confirm = "unsure"')
    daemon.config_file.write_text(text, encoding="utf-8")
    daemon.send_signal(signal.SIGHUP)
    try:
        time.sleep(2)
        with daemon.client() as client:
            task = client.submit(text=TASK, follow=True)
            names = [e["event"] for e in follow(client, task)]
            assert "confirm" not in names and names[-1] == "done", names
            task, question, before = _asked(client, UNSURE)
            assert question["confidence"] < UNSURE_BELOW and question["reasons"], question
            _accepted_and_run(client, task, before)
    finally:
        daemon.config_file.write_text(text.replace('confirm = "unsure"', 'confirm = "always"'), encoding="utf-8")
        daemon.send_signal(signal.SIGHUP)
        time.sleep(2)


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
