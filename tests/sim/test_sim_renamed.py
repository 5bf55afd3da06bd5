"""Every keyword renamed in the profile, and the simulator runs fetch-and-return to the end:
`nrtrans run-program --profile` as a user runs it."""

from __future__ import annotations

import json
from pathlib import Path

from tests.sim.renamed import FETCH_AND_RETURN, write_renamed_profile
from tests.sim.test_sim_cli import run, write


def test_a_profile_with_every_keyword_renamed_fetches_and_returns(tmp_path: Path) -> None:
    profile = write_renamed_profile(tmp_path)
    program = write(tmp_path, FETCH_AND_RETURN)
    done = run([str(program), "--profile", str(profile), "--json"], tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["status"] == "done"
    assert [s["statement"] for s in report["steps"]] == ["sense;", "closein table;", "clutch cup;", "travel 0, 0;"]
    state = report["final_state"]
    assert state["holding"] == "cup"
    assert abs(state["pose"]["x"]) < 0.01 and abs(state["pose"]["y"]) < 0.01
