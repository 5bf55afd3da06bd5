"""The recorded pictures read well: one label per place, no label over another, objects in view, captions."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from agent.executor import execute
from agent.record import Recorder, StepMark, _place_labels, _places
from agent.sim.robot import SimRobot
from rsl.compiler import compile_program
from rsl.profile import Profile


def _mark(index: int, x: float, y: float, status: str = "done") -> StepMark:
    return StepMark(index, f"step {index};", status, x, y, 0.0)


def test_steps_that_end_at_the_same_place_share_one_label() -> None:
    marks = [_mark(1, 1, 0), _mark(2, 1.01, 0), *(_mark(i, 0, 0) for i in range(3, 8)), _mark(8, 2, 0, "failed"),
             _mark(9, 0.02, -0.01)]
    places = _places(marks)
    assert [(p.text, p.status) for p in places] == [("1, 2", "done"), ("3-7, 9", "done"), ("8", "failed")]


def test_labels_are_placed_where_they_overlap_nothing() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(8, 8), dpi=100)
    axes.set_xlim(-4.7, 3.7)
    axes.set_ylim(-3.3, 2.7)
    axes.set_aspect("equal")
    # The default scene's crowded corners: the bottle on the table, the tool on the workbench,
    # and several steps that ended at the start with the held cup.
    labels = [("table", 3.0, 0.0, "black", 9), ("bottle", 2.7, -0.3, "black", 9), ("cup", 2.68, 0.25, "black", 9),
              ("workbench", -2.5, -2.6, "black", 9), ("tool", -2.5, -2.4, "black", 9),
              ("cup (held)", 0.0, 0.0, "black", 9), ("7-13, 16", 0.0, 0.0, "tab:blue", 8), ("1, 2", 0.0, 0.02, "k", 8)]
    key = axes.legend(handles=axes.plot([0], [0], label="robot path"), loc="upper right")
    _place_labels(figure, axes, labels, avoid=[key])
    renderer = figure.canvas.get_renderer()
    boxes = [text.get_window_extent(renderer) for text in axes.texts]
    assert len(boxes) == len(labels)
    for i, a in enumerate(boxes):
        assert not a.overlaps(key.get_window_extent(renderer)), axes.texts[i].get_text()
        for j, b in enumerate(boxes[:i]):
            assert not a.overlaps(b), (axes.texts[i].get_text(), axes.texts[j].get_text())
    plt.close(figure)


def test_a_step_on_an_object_is_pictured_looking_at_it(robot: SimRobot, profile: Profile, tmp_path: Path) -> None:
    aimed: list[object] = []
    camera = robot.world.camera_image

    def watched(*args: object, look_at: object = None, **kwargs: object) -> np.ndarray:
        aimed.append(look_at)
        return camera(*args, look_at=look_at, **kwargs)  # type: ignore[arg-type]

    robot.world.camera_image = watched  # type: ignore[method-assign]
    plan = compile_program("turnleft 0.2; approach cup; grasp cup;", profile).plan
    recorder = Recorder(tmp_path, robot, gif=True)
    result = execute(plan, robot, profile, on_event=recorder.on_event)
    recorder.finish(result, title="test")
    assert result.ok
    cup = robot.world.objects()["cup"]
    assert aimed[0] is None  # turning names no object: the head camera as it is
    assert np.allclose(aimed[2], cup)  # the snapshot after grasping looks at the cup
    with Image.open(tmp_path / "run.gif") as gif:
        gif.seek(gif.n_frames - 1)
        frame = np.asarray(gif.convert("RGB"), dtype=int)
    band = frame[-20:]
    assert band.mean() < 60 and (band > 200).all(axis=2).sum() > 30  # white caption text on a black band


def test_a_program_from_standard_input_is_titled_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from agent.cli import main

    titles: list[str] = []
    finish = Recorder.finish

    def watched(self: Recorder, result: object = None, title: str = "") -> list[Path]:
        titles.append(title)
        return finish(self, result, title)  # type: ignore[arg-type]

    monkeypatch.setattr(Recorder, "finish", watched)
    monkeypatch.setattr("sys.stdin", io.StringIO("turnleft 0.2;\n"))
    assert main(["run-program", "-", "--record", str(tmp_path)]) == 0
    assert titles == ["program from standard input"]
    assert "recorded 2 picture(s)" in capsys.readouterr().err
