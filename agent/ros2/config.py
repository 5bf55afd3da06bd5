"""Every ROS 2 name and timing the backend and the bridge use, read from the profile.

The `[ros]` table of the robot profile is the one place a robot's topic,
service and joint names live; this module fills in defaults for the keys a
profile leaves out and rejects values of the wrong type with a clear message.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from rsl.profile import Profile, ProfileError


@dataclass(frozen=True)
class RosConfig:
    cmd_vel: str = "/cmd_vel"
    odom: str = "/odom"
    joint_states: str = "/joint_states"
    head_trajectory: str = "/head_controller/joint_trajectory"
    gripper_trajectory: str = "/gripper_controller/joint_trajectory"
    goal_pose: str = "/goal_pose"
    # The Trigger services of the perceive_objects and grasp_object primitives, named after them
    # unless the profile names them.
    perceive_service: str = "/perceive_objects"
    objects_topic: str = "/objects"
    grasp_service: str = "/grasp_object"
    head_pan_joint: str = "head_pan_joint"
    head_tilt_joint: str = "head_tilt_joint"
    gripper_joint: str = "gripper_joint"
    # Gripper joint positions (finger opening in metres on most grippers).
    gripper_open_position: float = 0.04
    gripper_closed_position: float = 0.0
    # The frame goal poses are given in; odometry's frame on the robots we target.
    world_frame: str = "odom"
    # Metres from a goal pose that count as arrived; at least the navigation stack's own
    # goal tolerance (Nav2's xy_goal_tolerance), or goals end as failures.
    goal_tolerance: float = 0.03
    # Seconds without odometry before a moving base is stopped and the step fails.
    odom_timeout: float = 0.5
    # Seconds to wait for the robot's first odometry before giving up on the link.
    connect_timeout: float = 10.0
    # Seconds a service (perceive, grasp) may take to answer.
    service_timeout: float = 5.0

    @classmethod
    def from_profile(cls, profile: Profile) -> RosConfig:
        return cls.from_mapping(profile.ros, source=profile.source or profile.name)

    @classmethod
    def from_mapping(cls, raw: dict[str, Any], source: str = "<profile>") -> RosConfig:
        known = {f.name: f for f in fields(cls)}
        unknown = sorted(set(raw) - set(known))
        if unknown:
            raise ProfileError(
                f"{source}: unknown [ros] settings: {', '.join(unknown)}; "
                f"the known ones are {', '.join(known)}"
            )
        values: dict[str, Any] = {}
        for key, value in raw.items():
            default = known[key].default
            if isinstance(default, float):
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise ProfileError(f"{source}: [ros] {key} must be a number, got {value!r}")
                if key.endswith("_timeout") and value <= 0:
                    raise ProfileError(f"{source}: [ros] {key} must be a positive number of seconds")
                if key == "goal_tolerance" and value <= 0:
                    raise ProfileError(f"{source}: [ros] goal_tolerance must be a positive number of metres")
                values[key] = float(value)
            else:
                if not isinstance(value, str) or not value:
                    raise ProfileError(f"{source}: [ros] {key} must be a non-empty name")
                values[key] = value
        return cls(**values)
