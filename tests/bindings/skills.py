"""Two skills added by profile alone, bound to ROS 2: `wave` (a joint trajectory on an arm joint),
`dock` (a std_srvs Trigger) and `lights` (a topic publish)."""

from __future__ import annotations

from rsl.profile import Profile, default_profile_path, parse_profile

ARM_TOPIC = "/arm_controller/joint_trajectory"
ARM_JOINT = "arm_shoulder_joint"
DOCK_SERVICE = "/dock"
LIGHTS_TOPIC = "/lights/level"

NEW_SKILLS = f"""
[[skills]]
keyword = "wave"
description = "Wave: swing the arm's shoulder to an angle and hold it there."
example = "wave 0.8;"
aliases = ["greet"]
params = [{{ name = "angle", kind = "number", unit = "rad", min = 0.1, max = 1.5 }}]
[skills.binding]
ros = "joint_trajectory"
topic = "{ARM_TOPIC}"
joints = ["{ARM_JOINT}"]
positions = ["angle"]
duration = 0.5

[[skills]]
keyword = "dock"
description = "Drive onto the charging dock."
example = "dock;"
aliases = ["charge"]
params = []
binding = {{ ros = "trigger", service = "{DOCK_SERVICE}" }}

[[skills]]
keyword = "lights"
description = "Set the brightness of the light ring."
example = "lights 0.5;"
params = [{{ name = "level", kind = "number", unit = "fraction", min = 0.01, max = 1.0 }}]
binding = {{ ros = "topic", topic = "{LIGHTS_TOPIC}", type = "std_msgs/msg/Float64", fields = {{ data = "level" }} }}
"""


def profile_text() -> str:
    return default_profile_path().read_text(encoding="utf-8") + NEW_SKILLS


def extended_profile() -> Profile:
    return parse_profile(profile_text(), source="extended.toml")
