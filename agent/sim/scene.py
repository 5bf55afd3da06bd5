"""Scene files: where the robot starts and which named objects are around it.

A scene is a TOML file:

    [start]
    x = 0.0
    y = 0.0
    heading = 0.0          # rad, counter-clockwise from +x

    [[objects]]
    name = "cup"
    x = 2.0
    y = 0.0
    z = 0.8                # height of the object's centre; 0 = half its height
    kind = "graspable"     # or "furniture" (cannot be picked up) or "fixed" (never moves)
    shape = "cylinder"     # box, cylinder or sphere
    size = [0.08, 0.08, 0.12]   # extent along x, y, z in metres
    mass = 0.2             # kg
    yaw = 0.0
    color = [0.9, 0.9, 0.9]
"""

from __future__ import annotations

import dataclasses
import math
import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from agent.robot import Pose
from rsl.settings import read_settings, setting

KINDS = ("graspable", "furniture", "fixed")
SHAPES = ("box", "cylinder", "sphere")
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
ORIGIN = Pose(0.0, 0.0, 0.0)


class SceneError(ValueError):
    """A scene file that cannot be used, with where and what to fix."""


@dataclass(frozen=True)
class SceneObject:
    """One `[[objects]]` table."""

    name: str = setting(doc="what programs call it: an identifier like `cup` or `red_ball`")
    x: float = setting(doc="m, world frame; every object needs x and y")
    y: float = setting(doc="m, world frame; every object needs x and y")
    # Not given in the file: half the object's height, so it stands on the floor.
    z: float = setting(math.nan, doc="m, the height of the object's centre above the floor")
    kind: str = setting("graspable", choices=KINDS, doc="graspable, furniture (cannot be picked up) or fixed")
    shape: str = setting("box", choices=SHAPES, doc="box, cylinder or sphere")
    size: tuple[float, float, float] = setting((0.1, 0.1, 0.1), length=3, above=0.0,
                                               doc="m, extent along x, y and z")
    mass: float = setting(0.3, above=0.0, doc="kg")
    yaw: float = setting(0.0, doc="rad")
    color: tuple[float, float, float] = setting((0.6, 0.6, 0.6), length=3, min=0.0, max=1.0, doc="red, green, blue")

    @property
    def graspable(self) -> bool:
        return self.kind == "graspable"

    def footprint_radius(self, direction: float) -> float:
        """Distance from the centre to the object's edge seen along `direction` (rad, world frame).

        `approach` keeps its stand-off from this edge, so the robot stops in
        front of a table rather than inside it.
        """
        if self.shape != "box":
            return max(self.size[0], self.size[1]) / 2.0
        local = direction - self.yaw
        cx, sy = abs(math.cos(local)), abs(math.sin(local))
        half_x, half_y = self.size[0] / 2.0, self.size[1] / 2.0
        candidates = [half_x / cx if cx > 1e-9 else math.inf, half_y / sy if sy > 1e-9 else math.inf]
        return min(candidates)


@dataclass(frozen=True)
class Scene:
    objects: tuple[SceneObject, ...]
    start: Pose = ORIGIN
    name: str = "scene"

    def object(self, name: str) -> SceneObject | None:
        return next((o for o in self.objects if o.name == name), None)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(o.name for o in self.objects)


def default_scene_path() -> Path:
    return Path(str(resources.files("agent.sim") / "scenes" / "default.toml"))


def load_scene(path: str | Path | None = None) -> Scene:
    """Read a scene file; the default living-room-and-workshop scene when `path` is None."""
    scene_path = Path(path) if path is not None else default_scene_path()
    try:
        text = scene_path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError(
            f"cannot read scene file {scene_path}: {exc.strerror}\n"
            "  hint: pass an existing TOML file with --scene, or leave it out for the default scene"
        ) from exc
    return parse_scene(text, source=str(scene_path))


@dataclass(frozen=True)
class _Start:
    x: float = setting(0.0, doc="m")
    y: float = setting(0.0, doc="m")
    heading: float = setting(0.0, doc="rad, counter-clockwise from +x")


@dataclass(frozen=True)
class _SceneFile:
    start: _Start = field(default_factory=_Start, metadata={"doc": "where the robot starts"})
    objects: tuple[SceneObject, ...] = setting((), doc="the named objects")


def parse_scene(text: str, source: str = "<scene>") -> Scene:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source}: not valid TOML: {exc}") from exc
    scene = read_settings(_SceneFile, data, error=SceneError, source=source, docs="docs/simulator.md")
    objects: list[SceneObject] = []
    for index, obj in enumerate(scene.objects, start=1):
        if not _IDENTIFIER.match(obj.name):
            raise SceneError(f"{source}: objects[{index}].name {obj.name!r} must be an identifier like `cup` or "
                             "`red_ball`, because programs refer to it by name")
        if any(o.name == obj.name for o in objects):
            raise SceneError(f"{source}: object `{obj.name}` is declared twice; names must be unique")
        objects.append(dataclasses.replace(obj, z=obj.size[2] / 2.0) if math.isnan(obj.z) else obj)
    start = Pose(scene.start.x, scene.start.y, scene.start.heading)
    return Scene(objects=tuple(objects), start=start, name=Path(source).stem)
