"""`nrtrans translate` as a user runs it: exit codes, JSON contract, clear errors."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from agent.translate.confidence import UNSURE_BELOW

NRTRANS = [sys.executable, "-m", "agent.cli"]


def _run(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*NRTRANS, *args], capture_output=True, text=True, timeout=timeout,
                          env={**os.environ}, check=False)


def test_json_contract_and_exit_zero_when_verified(model_path: Path) -> None:
    done = _run("translate", "--json", "--model", str(model_path), "--objects", "cup", "grasp the cup")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert set(data) == {"task", "program", "verified", "passes", "attempts", "plan", "model", "timings_ms",
                         "explanation", "confidence", "doubts", "confirm", "refused"}
    assert data["verified"] is True and data["task"] == "grasp the cup"
    assert data["plan"] and all("skill" in c for c in data["plan"])
    assert data["explanation"] == "pick up the cup" and 0 <= data["confidence"] <= 1
    assert data["confirm"] is (data["confidence"] < UNSURE_BELOW) and data["refused"] is False
    plain = _run("translate", "--model", str(model_path), "--objects", "cup", "grasp the cup")
    assert plain.stdout == data["program"] and "-> pick up the cup" in plain.stderr


def test_a_refused_non_task_says_it_was_not_understood_not_that_the_program_is_wrong() -> None:
    done = _run("translate", "--adapter", "default", "what time is it")
    assert done.returncode == 1 and done.stdout == ""
    assert "was not understood as a task for this robot" in done.stderr
    assert "It can: drive straight ahead" in done.stderr
    assert "could not verify" not in done.stderr and "^" not in done.stderr


def test_exit_one_and_last_attempt_shown_when_not_verified(model_path: Path) -> None:
    done = _run("translate", "--model", str(model_path), "--objects", "cup", "--max-passes", "1",
                "grasp the mug")
    assert done.returncode == 1
    assert done.stdout == ""
    assert "could not verify" in done.stderr and "E104" in done.stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--model", "/nonexistent/model.gguf", "turn left"], "does not exist"),
        (["--max-passes", "0", "turn left"], "--max-passes must be at least 1"),
        (["   "], "the task is empty"),
        (["--endpoint", "ftp://example", "turn left"], "not an http(s) URL"),
        (["--split", "--no-split", "turn left"], "not allowed with argument"),
    ],
)
def test_bad_input_gets_a_clear_error_and_exit_two(args: list[str], message: str) -> None:
    done = _run("translate", *args, timeout=60)
    assert done.returncode == 2
    assert message in done.stderr


def test_help_lists_the_contract_flags() -> None:
    done = _run("translate", "--help", timeout=60)
    for flag in ["--json", "--model", "--adapter", "--max-passes", "--no-grammar", "--profile", "--objects",
                 "--endpoint"]:
        assert flag in done.stdout
