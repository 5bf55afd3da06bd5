"""The JSON formats nrtrans puts inside standard ROS 2 messages.

ROS 2 has no standard message for "the objects a robot knows about", and the
PyPI wheels carry no vision or manipulation packages, so object data travels as
JSON in fields every ROS 2 install has. docs/ros2.md documents the formats for
people wiring up a real robot; the backend and the bridge both use these
functions, so the two sides cannot drift apart.

- objects topic (std_msgs/String):
  `{"frame": "odom", "objects": {"cup": {"x": 1.0, "y": 0.5, "z": 0.8}}, "held": "cup"}`;
  an object may add its footprint, `"footprint": {"shape": "box", "size": [0.8, 1.2], "yaw": 0.0}`
  (shape box, cylinder or sphere), so approaching keeps its stand-off from the
  object's edge rather than its centre.
- perceive service (std_srvs/Trigger), on success the response message is
  `{"frame": "odom", "objects": {"cup": {"x": 1.0, "y": 0.5}}}` (the objects in view,
  footprints optional as above); on failure it is a sentence saying why.
- grasp service (std_srvs/Trigger) picks up the object nearest the gripper;
  on success the message is `{"held": "cup"}`, on failure a sentence saying why.
- bumper topic (std_msgs/String), one message each time the bumper stops the base:
  `{"frame": "odom", "obstacle": "table", "x": 2.6, "y": -0.2}`; `obstacle` is null
  when the robot cannot tell what it is, and the point of the base that was about to
  touch it (`x`, `y`) may be left out.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any


class FormatError(ValueError):
    """A message whose JSON does not follow the documented format."""


@dataclass(frozen=True)
class Footprint:
    shape: str  # box, cylinder or sphere
    size: tuple[float, float]  # extent along the object's own x and y, metres
    yaw: float = 0.0


@dataclass(frozen=True)
class ObjectReport:
    """Object positions in the world frame, what the gripper holds, and known footprints."""

    objects: dict[str, tuple[float, float]] = field(default_factory=dict)
    held: str | None = None
    frame: str = "odom"
    footprints: dict[str, Footprint] = field(default_factory=dict)


def encode_objects(objects: Mapping[str, tuple[float, ...]], held: str | None = None,
                   frame: str = "odom", footprints: Mapping[str, Footprint] | None = None) -> str:
    entries: dict[str, dict[str, object]] = {}
    for name, position in sorted(objects.items()):
        entry: dict[str, object] = {"x": round(position[0], 4), "y": round(position[1], 4)}
        if len(position) > 2:
            entry["z"] = round(position[2], 4)
        footprint = (footprints or {}).get(name)
        if footprint is not None:
            entry["footprint"] = {"shape": footprint.shape, "size": [round(v, 4) for v in footprint.size],
                                  "yaw": round(footprint.yaw, 4)}
        entries[name] = entry
    return json.dumps({"frame": frame, "objects": entries, "held": held}, separators=(",", ":"))


def decode_objects(text: str, where: str) -> ObjectReport:
    data = _load(text, where)
    raw_objects = data.get("objects", {})
    if not isinstance(raw_objects, dict):
        raise FormatError(f"{where}: `objects` must be a JSON object mapping names to {{\"x\", \"y\"}}")
    objects: dict[str, tuple[float, float]] = {}
    footprints: dict[str, Footprint] = {}
    for name, entry in raw_objects.items():
        try:
            x, y = float(entry["x"]), float(entry["y"])
        except (TypeError, KeyError, ValueError):
            raise FormatError(f"{where}: object `{name}` needs numeric `x` and `y`, got {entry!r}") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise FormatError(f"{where}: object `{name}` has a position that is not finite")
        objects[str(name)] = (x, y)
        if isinstance(entry, dict) and "footprint" in entry:
            footprints[str(name)] = _footprint(entry["footprint"], f"{where}: object `{name}`")
    held = data.get("held")
    if held is not None and not isinstance(held, str):
        raise FormatError(f"{where}: `held` must be an object name or null, got {held!r}")
    frame = data.get("frame", "odom")
    return ObjectReport(objects=objects, held=held or None, frame=str(frame), footprints=footprints)


def _footprint(raw: Any, where: str) -> Footprint:
    try:
        shape = raw["shape"]
        sx, sy = (float(v) for v in raw["size"])
        yaw = float(raw.get("yaw", 0.0))
    except (TypeError, KeyError, ValueError, AttributeError):
        raise FormatError(f"{where}: footprint must be {{\"shape\", \"size\": [x, y], \"yaw\"}}, "
                          f"got {raw!r}") from None
    if shape not in ("box", "cylinder", "sphere") or sx <= 0 or sy <= 0:
        raise FormatError(f"{where}: footprint shape must be box, cylinder or sphere with a positive size")
    return Footprint(str(shape), (sx, sy), yaw)


@dataclass(frozen=True)
class BumperStop:
    """The bumper stopped the base short of an obstacle."""

    obstacle: str | None = None  # None: the robot cannot tell what it is
    point: tuple[float, float] | None = None  # the point of the base about to touch it
    frame: str = "odom"


def encode_bumper(stop: BumperStop) -> str:
    data: dict[str, object] = {"frame": stop.frame, "obstacle": stop.obstacle}
    if stop.point is not None:
        data["x"], data["y"] = round(stop.point[0], 4), round(stop.point[1], 4)
    return json.dumps(data, separators=(",", ":"))


def decode_bumper(text: str, where: str) -> BumperStop:
    data = _load(text, where)
    obstacle = data.get("obstacle")
    if obstacle is not None and not isinstance(obstacle, str):
        raise FormatError(f"{where}: `obstacle` must be an object name or null, got {obstacle!r}")
    point = None
    if "x" in data or "y" in data:
        try:
            point = float(data["x"]), float(data["y"])
        except (TypeError, KeyError, ValueError):
            raise FormatError(f"{where}: `x` and `y` must both be numbers or both be left out, "
                              f"got {text[:120]!r}") from None
        if not all(math.isfinite(v) for v in point):
            raise FormatError(f"{where}: the point against the base is not finite")
    return BumperStop(obstacle or None, point, str(data.get("frame", "odom")))


def encode_held(held: str) -> str:
    return json.dumps({"held": held}, separators=(",", ":"))


def decode_held(text: str, where: str) -> str:
    held = _load(text, where).get("held")
    if not isinstance(held, str) or not held:
        raise FormatError(f"{where}: expected {{\"held\": \"NAME\"}} after a successful grasp, got {text!r}")
    return held


def _load(text: str, where: str) -> dict[str, Any]:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FormatError(
            f"{where}: not the documented JSON ({exc.msg} at char {exc.pos}): {text[:120]!r}"
        ) from None
    if not isinstance(data, dict):
        raise FormatError(f"{where}: expected a JSON object, got {text[:120]!r}")
    return data
