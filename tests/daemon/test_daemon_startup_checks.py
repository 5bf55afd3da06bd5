"""Start-up problems found before the model loads: one line each, no traceback, a non-zero exit."""

from __future__ import annotations

import subprocess
from pathlib import Path

from tests.daemon.conftest import NRTRANS, Daemon


def _serve(daemon: Daemon) -> tuple[int, list[str]]:
    result = subprocess.run(
        [NRTRANS, "serve", "--config", str(daemon.config_file)], capture_output=True, text=True, timeout=120
    )
    return result.returncode, result.stderr.splitlines()


def test_a_socket_directory_that_cannot_be_made_is_reported_before_the_model_loads(workdir: Path) -> None:
    blocker = workdir / "a-file"
    blocker.write_text("not a directory\n")
    daemon = Daemon(workdir, {"api": {"socket": str(blocker / "run" / "api.sock")}})
    code, lines = _serve(daemon)
    assert code != 0
    assert not any("Traceback" in line for line in lines), "\n".join(lines)
    assert not any("translation model" in line for line in lines), "checked before the model loads"
    errors = [line for line in lines if "error:" in line]
    assert len(errors) == 1, lines
    assert str(blocker / "run") in errors[0] and "not a directory" in errors[0] and "--socket" in errors[0]


def test_every_problem_is_one_line(workdir: Path) -> None:
    blocker = workdir / "a-file"
    blocker.write_text("")
    daemon = Daemon(workdir, {"api": {"socket": str(workdir / ("s" * 120) / "api.sock")}})
    text = daemon.config_file.read_text().replace(str(daemon.state_dir), str(blocker / "state"))
    daemon.config_file.write_text(text)
    code, lines = _serve(daemon)
    assert code != 0
    errors = [line for line in lines if line.startswith("nrtrans serve: error:")]
    assert len(errors) == 2 and lines == errors, lines
    assert "longer than 107 bytes" in errors[0]
    assert str(blocker / "state") in errors[1] and "--state-dir" in errors[1]


def test_a_path_in_the_way_of_the_socket_is_reported(workdir: Path) -> None:
    daemon = Daemon(workdir)
    daemon.socket.write_text("someone's file\n")
    code, lines = _serve(daemon)
    assert code != 0 and len(lines) == 1, lines
    assert "is not a socket" in lines[0] and str(daemon.socket) in lines[0]
    assert daemon.socket.read_text() == "someone's file\n", "nothing of the user's is removed"
