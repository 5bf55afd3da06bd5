"""`nrtrans demo`: the main job on the embedded defaults."""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    from agent.daemon.demo import DEFAULT_TASKS

    demo = subparsers.add_parser(
        "demo", help="start the daemon on the simulator with the bundled model and carry out a task",
        description="Start `nrtrans serve` on the simulator with the embedded model, wait until it is "
                    "ready, submit each TASK over its socket as `nrtrans send` would, print the events "
                    "up to the end of each task and where the pictures of its run are (trajectory plot, "
                    "animation, camera snapshots, under ~/.local/state/nrtrans/demo/pictures), then stop "
                    "the daemon. Exit status 0 when every task was done.")
    demo.add_argument("tasks", nargs="*", metavar="TASK", default=list(DEFAULT_TASKS),
                      help=f"tasks in plain English (default: {DEFAULT_TASKS[0]!r})")
    demo.add_argument("--realtime-factor", type=float, default=1.0, metavar="F",
                      help="simulated seconds per wall second; 0 runs as fast as possible (default: 1)")
    demo.set_defaults(func=_demo)


def _demo(args: argparse.Namespace) -> int:
    from agent.daemon.demo import run_demo

    return run_demo(args.tasks, realtime_factor=args.realtime_factor)
