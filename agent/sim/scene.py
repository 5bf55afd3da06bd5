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

import math
import re
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from agent.robot import Pose

KINDS = ("graspable", "furniture", "fixed")
SHAPES = ("box", "cylinder", "sphere")
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
ORIGIN = Pose(0.0, 0.0, 0.0)


class SceneError(ValueError):
    """A scene file that cannot be used, with where and what to fix."""


@dataclass(frozen=True)
class SceneObject:
    name: str
    x: float
    y: float
    z: float  # height of the centre above the floor
    kind: str = "graspable"
    shape: str = "box"
    size: tuple[float, float, float] = (0.1, 0.1, 0.1)
    mass: float = 0.3
    yaw: float = 0.0
    color: tuple[float, float, float] = (0.6, 0.6, 0.6)

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


def parse_scene(text: str, source: str = "<scene>") -> Scene:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source}: not valid TOML: {exc}") from exc
    start = data.get("start", {})
    try:
        pose = Pose(float(start.get("x", 0.0)), float(start.get("y", 0.0)), float(start.get("heading", 0.0)))
    except (TypeError, ValueError):
        raise SceneError(f"{source}: [start] x, y and heading must be numbers") from None
    objects: list[SceneObject] = []
    for index, raw in enumerate(data.get("objects", []), start=1):
        obj = _object(raw, f"{source}: object #{index}")
        if any(o.name == obj.name for o in objects):
            raise SceneError(f"{source}: object `{obj.name}` is declared twice; names must be unique")
        objects.append(obj)
    return Scene(objects=tuple(objects), start=pose, name=Path(source).stem)


def _object(raw: dict[str, Any], where: str) -> SceneObject:
    name = raw.get("name")
    if not isinstance(name, str) or not _IDENTIFIER.match(name):
        raise SceneError(f"{where}: name {name!r} must be an identifier like `cup` or `red_ball`, "
                         "because programs refer to it by name")
    where = f"{where} (`{name}`)"
    kind = raw.get("kind", "graspable")
    if kind not in KINDS:
        raise SceneError(f"{where}: kind {kind!r} must be one of {', '.join(KINDS)}")
    shape = raw.get("shape", "box")
    if shape not in SHAPES:
        raise SceneError(f"{where}: shape {shape!r} must be one of {', '.join(SHAPES)}")
    try:
        size = _triple(raw.get("size", (0.1, 0.1, 0.1)))
        color = _triple(raw.get("color", (0.6, 0.6, 0.6)))
        x, y = float(raw["x"]), float(raw["y"])
        z = float(raw.get("z", size[2] / 2.0))
        mass = float(raw.get("mass", 0.3))
        yaw = float(raw.get("yaw", 0.0))
    except KeyError as exc:
        raise SceneError(f"{where}: missing {exc.args[0]!r}; every object needs x and y") from None
    except (TypeError, ValueError):
        raise SceneError(f"{where}: x, y, z, mass and yaw must be numbers; size and color lists of three") \
            from None
    if min(size) <= 0 or mass <= 0:
        raise SceneError(f"{where}: size and mass must be positive")
    return SceneObject(name=name, x=x, y=y, z=z, kind=kind, shape=shape, size=size, mass=mass,
                       yaw=yaw, color=color)


def _triple(value: Any) -> tuple[float, float, float]:
    a, b, c = (float(v) for v in value)
    return a, b, c
