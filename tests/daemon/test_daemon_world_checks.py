"""World checks before motion, on the real simulator backend: refused plans never move the robot."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import pytest

from agent.daemon.config import parse_config
from agent.daemon.service import Service
from agent.daemon.tasks import Task, TaskState
from agent.daemon.world_checks import check_world
from rsl.compiler import compile_program


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Service]:
    state = tmp_path_factory.mktemp("world")
    config = parse_config(f'state_dir = "{state}"\n[speech]\nenabled = false\n'
                          '[translator]\nwarmup = false\n[robot]\nrealtime_factor = 0.0\n')
    running = Service(config)
    running.load()
    yield running
    running.shutdown()


def _run(service: Service, rsl: str) -> tuple[Task, list[Any]]:
    seen: list[Any] = []
    ended = threading.Event()

    def record(event: Any) -> None:
        seen.append(event)
        if event.name in ("done", "failed", "rejected", "cancelled"):
            ended.set()

    task, _ = service.submit(source="api", rsl=rsl)
    service.events.subscribe(record, task.id)
    assert ended.wait(120) or task.state.finished, [e.name for e in seen]
    return task, seen


def test_an_object_the_robot_does_not_know_is_refused_before_motion(service: Service) -> None:
    before = service.robot.state().pose
    task, seen = _run(service, "forward 0.2; grasp red_mug;")
    assert task.state is TaskState.REJECTED and "knows no red_mug" in task.reason and "cup" in task.reason
    assert not any(e.name == "executing" for e in seen)
    assert service.robot.state().pose == before


def test_a_drive_through_a_known_obstacle_is_refused_before_motion(service: Service) -> None:
    looked, _ = _run(service, "perceive;")
    assert looked.state is TaskState.DONE and "table" in {n for n, _x, _y in service.robot.state().known_objects}
    before = service.robot.state().pose
    task, seen = _run(service, "forward 4;")
    assert task.state is TaskState.REJECTED, task.reason
    assert "would drive into the table" in task.reason and "approach table" in task.reason
    assert not any(e.name == "executing" for e in seen)
    assert service.robot.state().pose == before


def test_a_grasp_out_of_reach_gets_the_approach_the_profile_declares(service: Service) -> None:
    plan = compile_program("grasp cup;", service.profile).plan
    assert plan is not None
    checked = check_world(plan, service.profile, service.robot)
    assert checked.added == ("approach cup;",)
    assert checked.plan is not None and checked.plan.to_rsl() == "approach cup;\ngrasp cup;\n"


def test_a_clear_drive_and_a_known_object_pass_unchanged(service: Service) -> None:
    plan = compile_program("turnleft 1.5708; forward 1; lookleft 0.3;", service.profile).plan
    assert plan is not None
    assert check_world(plan, service.profile, service.robot).plan == plan
