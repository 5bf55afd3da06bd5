"""Planar geometry shared by the backend and the bridge: headings and quaternions."""

from __future__ import annotations

import math


def wrap_angle(angle: float) -> float:
    """The same angle in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quaternion_from_yaw(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by `yaw` about +z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def footprint_radius(shape: str, size: tuple[float, float], yaw: float, direction: float) -> float:
    """Distance from an object's centre to its edge, seen along `direction` (world frame).

    Boxes are measured along the ray; round shapes by their radius. This is the
    convention the simulator's scenes use, so approaching a table stops at the
    same place on both backends.
    """
    if shape != "box":
        return max(size) / 2.0
    local = direction - yaw
    along_x, along_y = abs(math.cos(local)), abs(math.sin(local))
    half_x, half_y = size[0] / 2.0, size[1] / 2.0
    return min(half_x / along_x if along_x > 1e-9 else math.inf,
               half_y / along_y if along_y > 1e-9 else math.inf)
