"""`nrtrans sim-bridge`: serve the pybullet simulator over the robot's ROS 2 interfaces."""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from typing import Any

EXIT_OK, EXIT_USAGE, EXIT_NO_ROS = 0, 2, 3


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "sim-bridge", help="serve the simulated robot over ROS 2 topics and services",
        description="Run the pybullet robot as if it were a ROS 2 robot: it drives on cmd_vel, "
                    "publishes odom, joint_states and objects, follows goal_pose, runs head and "
                    "gripper joint trajectories, and offers the perceive and grasp services, with "
                    "every name taken from the profile's [ros] table (see docs/ros2.md); only the "
                    "interfaces the profile's skills are bound to are served. Then "
                    "`nrtrans run-program --backend ros2` drives it like a real robot. Runs until "
                    "SIGINT or SIGTERM, then stops the simulated base and exits 0.",
        epilog="Set ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST the same way on both "
               "sides to keep the traffic on this machine.")
    parser.add_argument("--scene", metavar="FILE", help="scene TOML with named objects (default: built-in room)")
    parser.add_argument("--profile", metavar="FILE", help="robot profile TOML (default: built-in robot)")
    parser.add_argument("--realtime-factor", metavar="F", type=float, default=1.0,
                        help="simulated seconds per wall second (default 1.0; 2 runs twice as fast)")
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    # Installed first, so a SIGTERM during the slow imports still ends in a clean exit 0.
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())

    from agent.sim.scene import SceneError, load_scene
    from rsl.profile import ProfileError, load_profile

    if not args.realtime_factor > 0:
        print(f"nrtrans sim-bridge: --realtime-factor must be positive, got {args.realtime_factor:g}",
              file=sys.stderr)
        return EXIT_USAGE
    try:
        profile = load_profile(args.profile)
        scene = load_scene(args.scene)
        from agent.ros2.config import RosConfig

        config = RosConfig.from_profile(profile)
    except (ProfileError, SceneError) as exc:
        print(f"nrtrans sim-bridge: {exc}", file=sys.stderr)
        return EXIT_USAGE
    try:
        import rclpy  # noqa: F401
    except ImportError as exc:
        print(f"nrtrans sim-bridge: ROS 2 is not available ({exc}).\n"
              "  Install the wheels with `pip install 'nrtrans[ros]'`, or source your ROS 2 "
              "distribution's setup.bash in a venv made with --system-site-packages (docs/ros2.md).",
              file=sys.stderr)
        return EXIT_NO_ROS

    from agent.ros2.bridge import SimBridge
    from agent.sim.world import SimWorld

    print(f"sim-bridge: loading scene `{scene.name}` ({len(scene.objects)} objects)", file=sys.stderr, flush=True)
    bridge = SimBridge(profile, lambda: SimWorld(profile, scene), realtime_factor=args.realtime_factor,
                       config=config)
    try:
        print(f"sim-bridge: serving {', '.join(bridge.interfaces)} for profile {profile.name} "
              f"on ROS_DOMAIN_ID={os.environ.get('ROS_DOMAIN_ID', '0')} "
              f"at {args.realtime_factor:g}x real time; Ctrl-C to stop", file=sys.stderr, flush=True)
        while not stop.wait(0.5):
            pass
    finally:
        bridge.close()
    print("sim-bridge: stopped", file=sys.stderr, flush=True)
    return EXIT_OK
