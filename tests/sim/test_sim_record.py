"""Pictures of a run: the trajectory plot, camera snapshots and the animation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from agent.executor import execute
from agent.record import Recorder
from agent.robot import Outcome, RobotState
from agent.sim.robot import SimRobot
from rsl.compiler import compile_program
from rsl.profile import Profile


class CameralessRobot:
    """The pybullet robot seen only through the robot interface, as a ROS 2 robot is."""

    def __init__(self, robot: SimRobot) -> None:
        self._robot = robot

    def __getattr__(self, skill: str):
        if skill == "world":
            raise AttributeError(skill)
        return getattr(self._robot, skill)

    def stop(self) -> None:
        self._robot.stop()

    def state(self) -> RobotState:
        return self._robot.state()

    def close(self) -> None:
        self._robot.close()


def _run(robot, profile: Profile, program: str, directory: Path, gif: bool = False):
    plan = compile_program(program, profile).plan
    recorder = Recorder(directory, robot, gif=gif)
    result = execute(plan, robot, profile, on_event=recorder.on_event)
    return result, recorder, recorder.finish(result, title="test")


def test_the_plot_shows_the_path_where_it_went(robot: SimRobot, profile: Profile, tmp_path: Path) -> None:
    result, recorder, written = _run(robot, profile, "forward 1; turnleft 1.5708; forward 1;", tmp_path, gif=True)
    assert result.ok
    assert [p.name for p in written] == ["trajectory.png", "step_01_forward.png", "step_02_turnleft.png",
                                         "step_03_forward.png", "run.gif"]
    xs, ys = zip(*recorder.path, strict=True)
    assert max(xs) > 0.95 and max(ys) > 0.95  # the path has both legs of the L
    assert [(m.index, m.status) for m in recorder.marks] == [(1, "done"), (2, "done"), (3, "done")]
    plot = np.asarray(Image.open(tmp_path / "trajectory.png").convert("RGB"))
    blue = (abs(plot[..., 0].astype(int) - 31) < 30) & (abs(plot[..., 2].astype(int) - 180) < 40)
    assert blue.sum() > 200  # the path is drawn in its colour
    with Image.open(tmp_path / "run.gif") as gif:
        assert gif.n_frames >= int(robot.world.sim_time / 0.2) - 1


def test_a_failed_step_is_marked_and_snapshots_differ(robot: SimRobot, profile: Profile, tmp_path: Path) -> None:
    result, recorder, _ = _run(robot, profile, "perceive; turnleft 3.1416; perceive; grasp cup;", tmp_path)
    assert not result.ok and recorder.marks[-1].status == "failed"
    first = np.asarray(Image.open(tmp_path / "step_01_perceive.png"), dtype=int)
    turned = np.asarray(Image.open(tmp_path / "step_03_perceive.png"), dtype=int)
    assert np.abs(first - turned).mean() > 1.0  # the camera turned with the robot


def test_a_backend_without_a_camera_still_gets_a_plot(robot: SimRobot, profile: Profile, tmp_path: Path) -> None:
    cameraless = CameralessRobot(robot)
    result, recorder, written = _run(cameraless, profile, "perceive; forward 0.5; turnright 1;", tmp_path, gif=True)
    assert result.ok
    assert [p.name for p in written] == ["trajectory.png"]
    assert len(recorder.path) == 4  # the start and each step's end
    assert recorder.path[1:] == [(m.x, m.y) for m in recorder.marks]
    assert recorder.path[2][0] > 0.45
    assert Outcome.done("saw bottle, cup, table") in result.outcomes
