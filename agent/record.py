"""Pictures of a run, so a person can see what the robot did (`run-program --record DIR`).

Written into the directory:

- `trajectory.png`: a top-down plot of the path, the objects, and where each
  step ended;
- `step_NN_<skill>.png`: what the head camera saw at the end of each step,
  aimed at the object when the step names one (simulator only);
- `run.gif` with `gif=True`: an animation from a camera following the robot,
  each frame captioned with the step it shows (simulator only).

With the simulator every physics step is on record; with another backend the
plot has the poses the robot reported at the start and at each step's end.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from agent.executor import ExecutionResult, StepEvent
from agent.robot import Robot

TRACE_EVERY = 4  # physics steps between trajectory points (30 Hz at 120 Hz physics)
GIF_PERIOD = 0.2  # s of simulated time between animation frames
GIF_SIZE = (320, 240)
GIF_MAX_FRAMES = 300  # beyond this the animation keeps every other frame, so memory stays bounded
SAME_PLACE = 0.08  # m: steps that ended closer than this share one label on the plot
LABEL_GAP = 2.0  # pixels kept free between two labels on the plot


@dataclass(frozen=True)
class StepMark:
    index: int
    statement: str
    status: str
    x: float
    y: float
    heading: float


class Recorder:
    """Collects a run's trajectory and pictures; attach `on_event` to the executor, then `finish()`."""

    def __init__(self, directory: str | Path, robot: Robot, *, gif: bool = False) -> None:
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.robot = robot
        self.world: Any = getattr(robot, "world", None)  # a SimWorld when the backend is the simulator
        self.gif = gif and self.world is not None
        self.path: list[tuple[float, float]] = []
        self.marks: list[StepMark] = []
        self.snapshots: list[Path] = []
        self._frames: list[Any] = []
        self._caption = "start"
        self._font: Any = None
        self._ticks = 0
        self._next_frame = 0.0
        self._period = GIF_PERIOD
        start = robot.state().pose
        self.start = (start.x, start.y, start.heading)
        self.path.append((start.x, start.y))
        if self.world is not None:
            self.world.add_listener(self._on_physics)
            if self.gif:
                self._frames.append(self._captioned(self.world.overview_image(*GIF_SIZE)))
                self._next_frame = self.world.sim_time + GIF_PERIOD

    def _on_physics(self, world: Any) -> None:
        self._ticks += 1
        if self._ticks % TRACE_EVERY == 0:
            sample = world.last
            self.path.append((sample.x, sample.y))
        if self.gif and world.sim_time >= self._next_frame:
            self._next_frame = world.sim_time + self._period
            self._frames.append(self._captioned(world.overview_image(*GIF_SIZE)))
            if len(self._frames) > GIF_MAX_FRAMES:
                self._frames = self._frames[::2]
                self._period *= 2

    def on_event(self, event: StepEvent) -> None:
        if event.outcome is None:
            self._caption = f"{event.index}/{event.total} {event.statement}"
            return
        self._caption = f"{event.index}/{event.total} {event.statement} {event.outcome.status.value}"
        pose = self.robot.state().pose
        if self.world is None:
            self.path.append((pose.x, pose.y))
        self.marks.append(StepMark(event.index, event.statement, event.outcome.status.value,
                                   pose.x, pose.y, pose.heading))
        if self.world is not None:
            from PIL import Image

            skill = event.statement.split()[0].rstrip(";")
            path = self.directory / f"step_{event.index:02d}_{skill}.png"
            Image.fromarray(self.world.camera_image(look_at=self._named_object(event.statement))).save(path)
            self.snapshots.append(path)

    def _named_object(self, statement: str) -> tuple[float, float, float] | None:
        """Where the first scene object the statement names is, so its snapshot can show it."""
        positions = self.world.objects()
        for word in re.findall(r"[A-Za-z_]\w*", statement):
            if word in positions:
                return positions[word]
        return None

    def _captioned(self, frame: Any) -> Any:
        """The frame with the step it shows written across its bottom."""
        from PIL import Image, ImageDraw, ImageFont

        if self._font is None:
            try:
                self._font = ImageFont.load_default(size=13)
            except (TypeError, OSError):  # Pillow without FreeType: the small bitmap font
                self._font = ImageFont.load_default()
        image = Image.fromarray(frame)
        draw = ImageDraw.Draw(image)
        height = image.height
        draw.rectangle((0, height - 20, image.width, height), fill=(0, 0, 0))
        draw.text((4, height - 18), self._caption, fill=(255, 255, 255), font=self._font)
        return image

    def finish(self, result: ExecutionResult | None = None, title: str = "") -> list[Path]:
        """Write the pictures; returns their paths (the plot first)."""
        if self.world is not None:
            self.world.remove_listener(self._on_physics)
        written = [self._plot(result, title), *self.snapshots]
        if self.gif and self._frames:
            written.append(self._animation())
        return written

    # -- pictures ------------------------------------------------------------------------------

    def _objects(self, result: ExecutionResult | None) -> list[dict[str, Any]]:
        if self.world is not None:
            positions = self.world.objects()
            return [{"name": o.name, "x": positions[o.name][0], "y": positions[o.name][1], "shape": o.shape,
                     "size": o.size, "yaw": o.yaw, "color": o.color, "start": (o.x, o.y)}
                    for o in self.world.scene.objects]
        state = result.final_state if result is not None else None
        known = state.known_objects if state is not None else ()
        return [{"name": n, "x": x, "y": y, "shape": "sphere", "size": (0.15, 0.15, 0.15), "yaw": 0.0,
                 "color": (0.5, 0.5, 0.5), "start": (x, y)} for n, x, y in known]

    def _plot(self, result: ExecutionResult | None, title: str) -> Path:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.patches import Circle, FancyArrow, Rectangle
        from matplotlib.transforms import Affine2D

        figure, axes = plt.subplots(figsize=(8, 8), dpi=100)
        labels: list[tuple[str, float, float, str, int]] = []
        holding = result.final_state.holding if result is not None and result.final_state is not None else None
        for obj in self._objects(result):
            sx, sy = obj["size"][0], obj["size"][1]
            if obj["shape"] == "box":
                patch: Any = Rectangle((obj["x"] - sx / 2, obj["y"] - sy / 2), sx, sy, facecolor=obj["color"],
                                       edgecolor="black", alpha=0.8)
                patch.set_transform(Affine2D().rotate_around(obj["x"], obj["y"], obj["yaw"]) + axes.transData)
            else:
                patch = Circle((obj["x"], obj["y"]), max(sx, sy) / 2, facecolor=obj["color"], edgecolor="black",
                               alpha=0.8)
            axes.add_patch(patch)
            moved = math.dist(obj["start"], (obj["x"], obj["y"])) > 0.05
            if moved:
                axes.plot([obj["start"][0], obj["x"]], [obj["start"][1], obj["y"]], ":", color=obj["color"])
            label = obj["name"] + (" (held)" if obj["name"] == holding else "")
            labels.append((label, obj["x"], obj["y"], "black", 9))
        xs, ys = zip(*self.path, strict=True)
        axes.plot(xs, ys, "-", color="tab:blue", linewidth=2, label="robot path")
        self._arrow(axes, FancyArrow, *self.start, "tab:green", "start")
        for place in _places(self.marks):
            color = {"done": "tab:blue", "failed": "tab:red", "cancelled": "tab:orange"}[place.status]
            axes.plot(place.x, place.y, "o", color=color, markersize=5)
            labels.append((place.text, place.x, place.y, color, 8))
        if self.marks:
            last = self.marks[-1]
            self._arrow(axes, FancyArrow, last.x, last.y, last.heading, "tab:purple", "end")
        self._frame(axes, xs, ys)
        axes.set_aspect("equal")
        axes.grid(True, alpha=0.3)
        axes.set_xlabel("x (m)")
        axes.set_ylabel("y (m)")
        status = result.status.value if result is not None else ""
        axes.set_title(f"{title} {status}".strip(), fontsize=10)
        legend = [f"{m.index}. {m.statement} {m.status}" for m in self.marks]
        if legend:
            axes.text(1.02, 1.0, "\n".join(legend[-40:]), transform=axes.transAxes, fontsize=8,
                      family="monospace", va="top")
        key = axes.legend(loc="upper right", fontsize=8)
        _place_labels(figure, axes, labels, avoid=[key])
        path = self.directory / "trajectory.png"
        figure.savefig(path, bbox_inches="tight")
        plt.close(figure)
        return path

    @staticmethod
    def _arrow(axes: Any, arrow: Any, x: float, y: float, heading: float, color: str, label: str) -> None:
        axes.add_patch(arrow(x, y, 0.3 * math.cos(heading), 0.3 * math.sin(heading), width=0.04,
                             color=color, label=label))

    def _frame(self, axes: Any, xs: tuple[float, ...], ys: tuple[float, ...]) -> None:
        # Show the path and everything near it, not the whole workspace.
        points_x = [*xs, *(o["x"] for o in self._objects(None))]
        points_y = [*ys, *(o["y"] for o in self._objects(None))]
        low_x, high_x = min(points_x) - 0.7, max(points_x) + 0.7
        low_y, high_y = min(points_y) - 0.7, max(points_y) + 0.7
        axes.set_xlim(low_x, high_x)
        axes.set_ylim(low_y, high_y)

    def _animation(self) -> Path:
        path = self.directory / "run.gif"
        frames = self._frames
        frames[0].save(path, save_all=True, append_images=frames[1:], duration=int(self._period * 1000), loop=0)
        return path


@dataclass(frozen=True)
class Place:
    """Where one or more steps ended, labelled with their numbers ("1, 2", "9-13, 16")."""

    text: str
    x: float
    y: float
    status: str  # the worst of the steps that ended here


def _places(marks: list[StepMark]) -> list[Place]:
    groups: list[list[StepMark]] = []
    for mark in marks:
        for group in groups:
            if math.dist((group[0].x, group[0].y), (mark.x, mark.y)) < SAME_PLACE:
                group.append(mark)
                break
        else:
            groups.append([mark])
    places = []
    for group in groups:
        statuses = {m.status for m in group}
        status = next((s for s in ("failed", "cancelled") if s in statuses), "done")
        places.append(Place(_numbers([m.index for m in group]), group[0].x, group[0].y, status))
    return places


def _numbers(indices: list[int]) -> str:
    """`[1, 2, 9, 10, 11, 16]` -> "1, 2, 9-11, 16": runs of three or more collapse."""
    runs: list[list[int]] = []
    for index in indices:
        if runs and index == runs[-1][-1] + 1:
            runs[-1].append(index)
        else:
            runs.append([index])
    parts = []
    for run in runs:
        parts.extend([f"{run[0]}-{run[-1]}"] if len(run) >= 3 else [str(i) for i in run])
    return ", ".join(parts)


# Offsets (points) and alignments tried in turn for a label, nearest first.
_SPOTS = [(dx * far, dy * far, ha, va) for far in (1.0, 2.5, 4.5) for dx, dy, ha, va in (
    (6, 6, "left", "bottom"), (6, -6, "left", "top"), (-6, 6, "right", "bottom"), (-6, -6, "right", "top"),
    (8, 0, "left", "center"), (-8, 0, "right", "center"), (0, 8, "center", "bottom"), (0, -8, "center", "top"))]


def _place_labels(figure: Any, axes: Any, labels: list[tuple[str, float, float, str, int]], avoid: list[Any]) -> None:
    """Annotate each point, choosing for each label the nearest spot where it overlaps no earlier one."""
    figure.canvas.draw()  # the layout is final, so the labels' extents are what will be saved
    renderer = figure.canvas.get_renderer()
    taken = [artist.get_window_extent(renderer) for artist in avoid]
    for text, x, y, color, size in labels:
        best: tuple[float, Any, Any] | None = None
        for dx, dy, ha, va in _SPOTS:
            note = axes.annotate(text, (x, y), textcoords="offset points", xytext=(dx, dy), ha=ha, va=va,
                                 fontsize=size, color=color)
            box = note.get_window_extent(renderer).padded(LABEL_GAP)
            overlap = sum(_overlap(box, other) for other in taken)
            if best is None or overlap < best[0]:
                if best is not None:
                    best[1].remove()
                best = (overlap, note, box)
            else:
                note.remove()
            if overlap == 0:
                break
        assert best is not None
        taken.append(best[2])


def _overlap(a: Any, b: Any) -> float:
    width = min(a.x1, b.x1) - max(a.x0, b.x0)
    height = min(a.y1, b.y1) - max(a.y0, b.y0)
    return width * height if width > 0 and height > 0 else 0.0
