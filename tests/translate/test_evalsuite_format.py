"""The suite format: a file's own groups, and non-tasks that are right only when nothing comes back."""

from __future__ import annotations

from pathlib import Path

import pytest

from agent.evalsuite.runner import TaskOutcome, summarize
from agent.evalsuite.suite import SuiteError, accepts, load_suite
from rsl.compiler import compile_program
from rsl.profile import load_profile

SUITE = '''
groups = ["everyday", "refuse"]

[[task]]
group = "everyday"
task = "robot, scoot forward a metre please"
accept = ["forward 1;"]

[[task]]
group = "refuse"
task = "thanks, that's all"
accept = []
refuse = true
'''


def test_a_suite_names_its_own_groups_and_refusals(tmp_path: Path) -> None:
    profile = load_profile()
    path = tmp_path / "suite.toml"
    path.write_text(SUITE, encoding="utf-8")
    task, non_task = load_suite(path, profile)
    plan = compile_program("forward 1;", profile).plan
    assert accepts(task, plan, profile) and not accepts(task, None, profile)
    assert accepts(non_task, None, profile) and not accepts(non_task, plan, profile)


def test_a_group_the_file_does_not_name_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "suite.toml"
    path.write_text(SUITE.replace('group = "refuse"', 'group = "chitchat"'), encoding="utf-8")
    with pytest.raises(SuiteError, match="chitchat"):
        load_suite(path)


def test_a_non_task_must_accept_nothing(tmp_path: Path) -> None:
    path = tmp_path / "suite.toml"
    path.write_text(SUITE.replace("accept = []\nrefuse", 'accept = ["perceive;"]\nrefuse'), encoding="utf-8")
    with pytest.raises(SuiteError, match="refuse = true"):
        load_suite(path)


def test_summary_counts_verified_programs_that_are_not_what_was_asked(tmp_path: Path) -> None:
    path = tmp_path / "suite.toml"
    path.write_text(SUITE, encoding="utf-8")
    task, non_task = load_suite(path)
    outcomes = [TaskOutcome(task=task, program="forward 1;", verified=True, accepted=True, passes=1, latency_ms=1),
                TaskOutcome(task=non_task, program="forward 1;", verified=True, accepted=False, passes=1,
                            latency_ms=1)]
    table = summarize(outcomes)
    assert list(table) == ["everyday", "refuse", "overall"]
    assert table["refuse"]["wrong_runs"] == 1.0 and table["everyday"]["wrong_runs"] == 0.0
    assert table["overall"]["wrong_runs"] == 0.5


# The sets translation is measured on (bench/written holds training pairs in another format).
BENCH = Path(__file__).parents[2] / "bench"
MEASURED_SETS = sorted(p for d in ("fresh", "practice") for p in (BENCH / d).glob("*.toml"))


@pytest.mark.parametrize("path", MEASURED_SETS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_every_bench_task_set_loads_and_its_programs_compile(path: Path) -> None:
    tasks = load_suite(path, load_profile())
    assert tasks and all(t.task for t in tasks)
