"""`nrtrans run-program` as a user runs it: a separate process, its exit status, stdout and files."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from PIL import Image

NRTRANS = [sys.executable, "-m", "agent.cli"]
REPO = Path(__file__).resolve().parents[2]


def run(args: list[str], cwd: Path, stdin: str | None = None, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([*NRTRANS, "run-program", *args], cwd=cwd, input=stdin, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "PYTHONPATH": str(REPO)})


def write(tmp_path: Path, text: str, name: str = "task.rsl") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_a_program_that_runs_exits_0_and_reports_json(tmp_path: Path) -> None:
    write(tmp_path, "perceive;\napproach table;\ngrasp cup;\ngoto 0, 0;\n")
    done = run(["task.rsl", "--json"], tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["status"] == "done"
    assert [s["statement"] for s in report["steps"]] == ["perceive;", "approach table;", "grasp cup;", "goto 0, 0;"]
    assert all(s["status"] == "done" for s in report["steps"])
    assert report["final_state"]["holding"] == "cup"
    assert abs(report["final_state"]["pose"]["x"]) < 0.05
    assert "[3/4] grasp cup; done" in done.stderr  # progress on stderr


def test_a_failing_step_exits_1_and_stops_there(tmp_path: Path) -> None:
    write(tmp_path, "perceive;\ngrasp cup;\nforward 1;\n")
    failed = run(["task.rsl", "--json"], tmp_path)
    assert failed.returncode == 1
    report = json.loads(failed.stdout)
    assert report["status"] == "failed"
    assert [s["status"] for s in report["steps"]] == ["done", "failed"]
    assert "out of reach 0.8 m" in report["steps"][1]["reason"]
    assert report["final_state"]["pose"]["x"] < 0.01  # `forward 1;` never ran


def test_an_unverified_program_is_never_dispatched(tmp_path: Path) -> None:
    write(tmp_path, "forward 1;\nForward 2;\ngrasp unicorn;\n")
    refused = run(["task.rsl", "--json", "--record", "rec"], tmp_path)
    assert refused.returncode == 1
    assert "E001" in refused.stderr or "keyword" in refused.stderr.lower()
    assert "unicorn" in refused.stderr  # not in the scene, so an unknown object
    assert "nothing was sent to the robot" in refused.stderr
    assert json.loads(refused.stdout)["status"] == "unverified"
    assert "[1/" not in refused.stderr and not (tmp_path / "rec").exists()


def test_dry_run_refuses_the_real_robot_when_the_simulator_fails(tmp_path: Path) -> None:
    write(tmp_path, "forward 1;\ngrasp cup;\n")
    refused = run(["task.rsl", "--backend", "ros2", "--dry-run", "--json"], tmp_path)
    assert refused.returncode == 1
    report = json.loads(refused.stdout)
    assert report["status"] == "refused"
    assert report["dry_run"]["status"] == "failed"
    assert "nothing was sent to the ros2 robot" in refused.stderr


def test_record_writes_a_plot_snapshots_and_a_gif(tmp_path: Path) -> None:
    write(tmp_path, "perceive;\nturnleft 1.5708;\nforward 0.5;\n")
    done = run(["task.rsl", "--record", "rec", "--gif"], tmp_path)
    assert done.returncode == 0, done.stderr
    rec = tmp_path / "rec"
    names = sorted(p.name for p in rec.iterdir())
    assert names == ["run.gif", "step_01_perceive.png", "step_02_turnleft.png", "step_03_forward.png",
                     "trajectory.png"]
    with Image.open(rec / "trajectory.png") as plot:
        assert plot.width > 400 and plot.height > 400
        assert len(plot.convert("RGB").getcolors(1 << 16) or ()) > 20  # a picture, not a blank
    with Image.open(rec / "step_01_perceive.png") as snapshot:
        assert snapshot.size == (320, 240)
    with Image.open(rec / "run.gif") as gif:
        assert gif.n_frames > 5


def test_stdin_and_usage_errors(tmp_path: Path) -> None:
    done = run(["-"], tmp_path, stdin="lookup 0.2;\n")
    assert done.returncode == 0, done.stderr
    missing = run(["nope.rsl"], tmp_path)
    assert missing.returncode == 2 and "cannot read the program nope.rsl" in missing.stderr
    write(tmp_path, "[[objects]]\nname = 'cup'\n", "bad.toml")
    bad_scene = run(["-", "--scene", "bad.toml"], tmp_path, stdin="perceive;\n")
    assert bad_scene.returncode == 2 and "every object needs x and y" in bad_scene.stderr


def test_sigterm_cancels_the_run_and_stops_the_robot(tmp_path: Path) -> None:
    write(tmp_path, "forward 5;\nturnleft 1;\n")
    process = subprocess.Popen([*NRTRANS, "run-program", "task.rsl", "--json", "--realtime-factor", "1"],
                               cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": str(REPO)})
    assert process.stderr is not None
    line = process.stderr.readline()
    while "[1/2] forward 5; ..." not in line:
        assert line, "run-program ended before the first step started"
        line = process.stderr.readline()
    time.sleep(1.0)
    process.send_signal(signal.SIGTERM)
    out, _err = process.communicate(timeout=30)
    assert process.returncode == 1
    report = json.loads(out)
    assert report["status"] == "cancelled"
    assert report["steps"] == [{"step": 1, "statement": "forward 5;", "status": "cancelled",
                                "reason": "interrupted by SIGTERM"}]
    assert 0.1 < report["final_state"]["pose"]["x"] < 1.0
