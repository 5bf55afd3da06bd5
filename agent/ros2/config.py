"""Every ROS 2 name and timing the backend and the bridge use, read from the profile.

The `[ros]` table of the robot profile is the one place a robot's topic,
service and joint names live; this module fills in defaults for the keys a
profile leaves out and, through rsl/settings.py, rejects unknown keys and
values of the wrong type or range with a clear message.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rsl.profile import Profile, ProfileError
from rsl.settings import read_settings, setting


def _name(default: str, doc: str) -> Any:
    return setting(default, doc=doc, nonempty=True)


def _seconds(default: float, doc: str) -> Any:
    return setting(default, doc=doc, above=0.0)


@dataclass(frozen=True)
class RosConfig:
    cmd_vel: str = _name("/cmd_vel", "base velocity commands (geometry_msgs/Twist)")
    odom: str = _name("/odom", "odometry (nav_msgs/Odometry)")
    joint_states: str = _name("/joint_states", "head and gripper joint feedback")
    head_trajectory: str = _name("/head_controller/joint_trajectory", "head JointTrajectory commands")
    gripper_trajectory: str = _name("/gripper_controller/joint_trajectory", "gripper JointTrajectory commands")
    goal_pose: str = _name("/goal_pose", "Nav2-style navigation goals (geometry_msgs/PoseStamped)")
    bumper: str = _name("/bumper", "bumper stops of the base (std_msgs/String, JSON); optional")
    # Named after the primitives they serve unless the profile names them.
    perceive_service: str = _name("/perceive_objects", "the perceive_objects primitive's Trigger service")
    objects_topic: str = _name("/objects", "object positions and what is held (std_msgs/String, JSON)")
    grasp_service: str = _name("/grasp_object", "the grasp_object primitive's Trigger service")
    head_pan_joint: str = _name("head_pan_joint", "the head's pan joint")
    head_tilt_joint: str = _name("head_tilt_joint", "the head's tilt joint")
    gripper_joint: str = _name("gripper_joint", "the gripper's joint")
    gripper_open_position: float = setting(0.04, doc="gripper joint position when open (finger opening, m)")
    gripper_closed_position: float = setting(0.0, doc="gripper joint position when closed")
    world_frame: str = _name("odom", "the frame goal poses are given in; odometry's frame on the robots we target")
    goal_tolerance: float = setting(0.03, above=0.0, doc=(
        "metres from a goal pose that count as arrived; at least the navigation stack's own goal tolerance "
        "(Nav2's xy_goal_tolerance), or goals end as failures"))
    odom_timeout: float = _seconds(0.5, "seconds without odometry before a moving base is stopped and the step fails")
    connect_timeout: float = _seconds(10.0, "seconds to wait for the robot's first odometry before giving up")
    service_timeout: float = _seconds(5.0, "seconds a primitive's service may take to answer")
    discovery_timeout: float = _seconds(10.0, (
        "seconds after the backend starts that DDS discovery may take to find a service or a topic's "
        "subscriber before it is called missing; after that, 2 s"))

    @classmethod
    def from_profile(cls, profile: Profile) -> RosConfig:
        return cls.from_mapping(profile.ros, source=profile.source or profile.name)

    @classmethod
    def from_mapping(cls, raw: dict[str, Any], source: str = "<profile>") -> RosConfig:
        return read_settings(cls, raw, error=ProfileError, source=source, prefix="ros.", docs="docs/ros2.md")
