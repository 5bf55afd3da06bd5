"""The simulator bridge's answer to a goal pose: turn towards it, drive, then turn
to the goal's heading. A stand-in for a navigation stack, not a planner: it
drives straight and leaves obstacle avoidance to real robots' Nav2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from agent.robot import Pose
from agent.ros2.geometry import wrap_angle
from rsl.profile import Motion

POSITION_TOLERANCE = 0.01  # m; the backend accepts 3 cm, so this settles well inside it
HEADING_TOLERANCE = math.radians(0.3)
REALIGN_DISTANCE = 0.05  # m; drifting this far while turning on the spot restarts the drive
DRIVE_HEADING_ERROR = 0.35  # rad; turn on the spot first when further off than this
GAIN = 3.0  # 1/s
# A new goal this close to the robot's pose means "stop here", the way clients cancel
# a goal: the robot stops at once instead of creeping back to where the goal was sent.
HOLD_DISTANCE = 0.02  # m
HOLD_ANGLE = math.radians(5.0)


@dataclass(frozen=True)
class Goal:
    x: float
    y: float
    heading: float


class GoalFollower:
    def __init__(self, motion: Motion) -> None:
        self.motion = motion
        self.goal: Goal | None = None
        self._aligning = False
        self._new = False
        self._command = (0.0, 0.0)

    def set(self, goal: Goal) -> None:
        self.goal = goal
        self._aligning = False
        self._new = True

    def clear(self) -> None:
        self.goal = None
        self._command = (0.0, 0.0)

    def command(self, pose: Pose, dt: float) -> tuple[float, float]:
        """The (linear, angular) velocity to command now; (0, 0) once the goal is reached."""
        goal = self.goal
        if goal is None:
            return 0.0, 0.0
        motion = self.motion
        dx, dy = goal.x - pose.x, goal.y - pose.y
        far = math.hypot(dx, dy)
        if self._new:
            self._new = False
            if far <= HOLD_DISTANCE and abs(wrap_angle(goal.heading - pose.heading)) <= HOLD_ANGLE:
                self.clear()
                return 0.0, 0.0
        if self._aligning and far > REALIGN_DISTANCE:
            self._aligning = False
        if not self._aligning and far > POSITION_TOLERANCE:
            error = wrap_angle(math.atan2(dy, dx) - pose.heading)
            direction = 1.0
            if far < 0.1 and abs(error) > math.pi / 2:
                # A small correction behind the robot: back up rather than turn around.
                error, direction = wrap_angle(error + math.pi), -1.0
            angular = _limit(GAIN * error, motion.max_angular_speed)
            linear = 0.0
            if abs(error) < DRIVE_HEADING_ERROR:
                speed = min(motion.max_linear_speed, math.sqrt(2.0 * motion.max_linear_accel * far),
                            max(GAIN * far, 0.02))
                linear = direction * speed * math.cos(error)
        else:
            self._aligning = True
            error = wrap_angle(goal.heading - pose.heading)
            if abs(error) <= HEADING_TOLERANCE:
                self.clear()
                return 0.0, 0.0
            speed = min(motion.max_angular_speed, math.sqrt(2.0 * motion.max_angular_accel * abs(error)),
                        max(GAIN * abs(error), 0.03))
            linear, angular = 0.0, math.copysign(speed, error)
        return self._ramp(linear, angular, dt)

    def _ramp(self, linear: float, angular: float, dt: float) -> tuple[float, float]:
        last_linear, last_angular = self._command
        linear = _speed_up(last_linear, linear, self.motion.max_linear_accel * dt)
        angular = _speed_up(last_angular, angular, self.motion.max_angular_accel * dt)
        self._command = (linear, angular)
        return linear, angular


def _speed_up(last: float, target: float, step: float) -> float:
    """Limit how fast the speed grows, but never delay braking: a goal at the robot's own
    pose is how clients stop it, and it must stop at once."""
    if last * target < 0:
        last = 0.0
    if abs(target) <= abs(last):
        return target
    return last + max(-step, min(step, target - last))


def _limit(value: float, bound: float) -> float:
    return max(-bound, min(bound, value))
