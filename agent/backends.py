"""Open a robot backend by name: the pybullet simulator or a ROS 2 robot."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from agent.robot import Robot
from rsl.profile import Profile

BACKENDS = ("sim", "ros2")


class BackendError(RuntimeError):
    """A backend that cannot be opened, with what to do about it."""


def open_robot(backend: str, profile: Profile, *, scene: str | Path | None = None, realtime_factor: float = 0.0,
               **options: Any) -> Robot:
    """The robot for `backend`: "sim" (the default robot, a pybullet world) or "ros2" (rclpy).

    `scene` and `realtime_factor` apply to the simulator only; other keyword
    options go to the ROS 2 backend (`agent.ros2.backend.Ros2Robot`).
    """
    if backend == "sim":
        from agent.sim.robot import SimRobot
        from agent.sim.scene import load_scene

        if options:
            raise BackendError(f"the sim backend takes no option(s) {', '.join(sorted(options))}; "
                               "only scene and realtime_factor")
        return SimRobot(profile, load_scene(scene), realtime_factor=realtime_factor)
    if backend == "ros2":
        try:
            from agent.ros2.backend import Ros2Robot
        except ImportError as exc:
            raise BackendError(
                f"the ros2 backend needs rclpy, which cannot be imported here: {exc}\n"
                "  hint: pip install 'nrtrans[ros]' (x86_64), or source your ROS 2 setup.bash (Jazzy or Kilted) "
                "before starting nrtrans; or use --backend sim"
            ) from exc
        return Ros2Robot(profile, **options)
    raise BackendError(f"unknown backend {backend!r}: choose one of {', '.join(BACKENDS)}")
