"""Speed profiles for closed-loop motion: pure functions, no ROS.

A move is driven by the distance still to go, measured from odometry each
cycle. Far from the goal the speed is limited by the profile's maximum and by
how fast it may ramp up; close to it, by the speed from which the robot can
still stop in the remaining distance at the allowed deceleration, and by a
proportional term that lets it creep the last millimetres without overshoot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Limits:
    max_speed: float
    max_accel: float
    gain: float  # 1/s, proportional gain near the goal
    creep: float  # the slowest speed worth commanding


def next_speed(remaining: float, previous: float, limits: Limits, dt: float) -> float:
    """The signed speed to command now, `remaining` being signed distance to go."""
    magnitude = abs(remaining)
    target = min(limits.max_speed,
                 math.sqrt(2.0 * limits.max_accel * magnitude),
                 max(limits.gain * magnitude, limits.creep))
    target = math.copysign(target, remaining)
    step = limits.max_accel * dt
    return min(max(target, previous - step), previous + step)


def move_budget(amount: float, max_speed: float, max_accel: float, margin: float) -> float:
    """Seconds a move of `amount` may take: the trapezoid time, slack for the slow
    final approach, and the profile's margin."""
    cruise = amount / max_speed + max_speed / max_accel
    return 1.5 * cruise + 2.0 + margin
