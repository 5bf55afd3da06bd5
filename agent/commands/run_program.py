"""`nrtrans run-program`: verify an RSL program and run it on the simulator or a ROS 2 robot."""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time
from pathlib import Path
from typing import Any

EXIT_DONE, EXIT_FAILED, EXIT_USAGE = 0, 1, 2


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "run-program", help="verify an RSL program and run it on the simulator or a robot",
        description="Compile an RSL program against the robot profile and, only if it verifies, run it\n"
                    "step by step on a backend: `sim` (a headless pybullet robot) or `ros2` (a robot,\n"
                    "or `nrtrans sim-bridge`, over ROS 2). Progress goes to standard error.\n\n"
                    "Exit status: 0 every step done; 1 the program does not verify, a step failed, or\n"
                    "the run was cancelled (SIGINT/SIGTERM stop the robot); 2 usage error or a backend\n"
                    "that cannot be opened. More in docs/simulator.md.",
        epilog="Examples:\n"
               "  nrtrans run-program task.rsl --record runs/one --gif\n"
               "  nrtrans run-program task.rsl --backend ros2 --dry-run --json\n"
               "  nrtrans translate \"pick up the cup\" --objects cup,table | nrtrans run-program -",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("program", metavar="FILE", help="the RSL program; `-` reads standard input")
    parser.add_argument("--backend", choices=("sim", "ros2"), default="sim",
                        help="where to run it (default: sim)")
    parser.add_argument("--scene", metavar="FILE",
                        help="simulator scene TOML with named objects (default: the built-in room; "
                             "see docs/simulator.md)")
    parser.add_argument("--dry-run", action="store_true",
                        help="run in the simulator first; dispatch to the ros2 backend only if every step "
                             "is done there")
    parser.add_argument("--record", metavar="DIR",
                        help="save pictures of the run to DIR: trajectory.png and camera snapshots per step")
    parser.add_argument("--gif", action="store_true", help="with --record on the simulator: also run.gif")
    parser.add_argument("--json", action="store_true",
                        help="print one JSON object: program, status, steps (statement, status, reason), "
                             "final_state, and dry_run when used")
    parser.add_argument("--profile", metavar="FILE", help="robot profile TOML (default: the built-in robot)")
    parser.add_argument("--objects", metavar="A,B",
                        help="object names the program may use (default: the scene's objects on sim, "
                             "unchecked on ros2)")
    parser.add_argument("--realtime-factor", metavar="F", type=float, default=0.0,
                        help="simulated seconds per wall second: 0 as fast as possible (default), 1 real time")
    parser.set_defaults(func=_run)


def _fail(message: str) -> int:
    print(f"nrtrans run-program: {message}", file=sys.stderr)
    return EXIT_USAGE


def _read(source: str) -> str:
    if source == "-":
        return sys.stdin.read()
    return Path(source).read_text(encoding="utf-8")


def _run(args: argparse.Namespace) -> int:
    from agent.robot import CancelToken
    from agent.sim.scene import SceneError, load_scene
    from rsl.compiler import compile_program
    from rsl.profile import ProfileError, load_profile

    if args.realtime_factor < 0:
        return _fail(f"--realtime-factor must be 0 or positive, got {args.realtime_factor:g}")
    if args.gif and not args.record:
        return _fail("--gif needs --record DIR, the folder to write run.gif to")
    try:
        source = _read(args.program)
    except (OSError, UnicodeDecodeError) as exc:
        return _fail(f"cannot read the program {args.program}: {exc}\n"
                     "  hint: give an RSL file, or `-` to read standard input")
    try:
        profile = load_profile(args.profile)
        scene = load_scene(args.scene) if args.backend == "sim" or args.dry_run else None
    except (ProfileError, SceneError) as exc:
        return _fail(str(exc))

    if args.objects is not None:
        known: list[str] | None = [n.strip() for n in args.objects.split(",") if n.strip()]
    else:
        known = list(scene.names) if scene is not None and args.backend == "sim" else None
    result = compile_program(source, profile, known)
    if not result.ok or result.plan is None:
        for diagnostic in result.diagnostics:
            print(diagnostic.render(), file=sys.stderr)
        count = len(result.diagnostics)
        print(f"nrtrans run-program: the program does not verify ({count} error{'s' * (count != 1)}); "
              "nothing was sent to the robot", file=sys.stderr)
        if args.json:
            print(json.dumps({"program": args.program, "status": "unverified",
                              "diagnostics": [d.to_dict() for d in result.diagnostics]}, indent=2))
        return EXIT_FAILED
    plan = result.plan

    cancel = CancelToken()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda number, _frame: cancel.set(f"interrupted by {signal.Signals(number).name}"))

    report: dict[str, Any] = {"program": args.program}
    if args.dry_run and args.backend != "sim":
        print("dry run in the simulator:", file=sys.stderr)
        rehearsal = _execute(plan, "sim", profile, args, cancel, record=None, scene=args.scene)
        if rehearsal is None:
            return EXIT_USAGE
        report["dry_run"] = _summary(rehearsal, plan)
        if not rehearsal.ok:
            print(f"nrtrans run-program: the dry run in the simulator did not finish "
                  f"({rehearsal.status.value}); nothing was sent to the {args.backend} robot", file=sys.stderr)
            report["status"] = "refused"
            if args.json:
                print(json.dumps(report, indent=2))
            return EXIT_FAILED
        print(f"dry run passed; running on {args.backend}:", file=sys.stderr)
    execution = _execute(plan, args.backend, profile, args, cancel, record=args.record, scene=args.scene)
    if execution is None:
        return EXIT_USAGE
    report.update(_summary(execution, plan))
    if args.json:
        print(json.dumps(report, indent=2))
    return EXIT_DONE if execution.ok else EXIT_FAILED


def _execute(plan: Any, backend: str, profile: Any, args: argparse.Namespace, cancel: Any, *,
             record: str | None, scene: str | None) -> Any:
    """Run `plan` on `backend`; None when the backend cannot be opened (the reason is printed)."""
    from agent.backends import open_robot
    from agent.executor import StepEvent, execute

    options: dict[str, Any] = {}
    if backend == "sim":
        options = {"scene": scene, "realtime_factor": args.realtime_factor}
    try:
        robot = open_robot(backend, profile, **options)
    except Exception as exc:
        _fail(f"cannot open the {backend} backend: {exc}")
        return None
    try:
        recorder = None
        if record is not None:
            from agent.record import Recorder

            recorder = Recorder(record, robot, gif=args.gif)
        started = time.monotonic()

        def on_event(event: StepEvent) -> None:
            if recorder is not None:
                recorder.on_event(event)
            prefix = f"[{event.index}/{event.total}] {event.statement}"
            if event.outcome is None:
                print(f"{prefix} ...", file=sys.stderr, flush=True)
            else:
                reason = f": {event.outcome.reason}" if event.outcome.reason else ""
                print(f"{prefix} {event.outcome.status.value}{reason} ({time.monotonic() - started:.1f} s)",
                      file=sys.stderr, flush=True)

        execution = execute(plan, robot, profile, cancel=cancel, on_event=on_event)
        if recorder is not None:
            title = "program from standard input" if args.program == "-" else Path(args.program).name
            written = recorder.finish(execution, title=title)
            print(f"recorded {len(written)} picture(s) in {record}", file=sys.stderr)
        return execution
    finally:
        robot.stop()
        robot.close()


def _summary(execution: Any, plan: Any) -> dict[str, Any]:
    steps = [{"step": i, "statement": command.to_rsl(), "status": outcome.status.value, "reason": outcome.reason}
             for i, (command, outcome) in enumerate(zip(plan.commands, execution.outcomes, strict=False), start=1)]
    state = execution.final_state.to_dict() if execution.final_state is not None else None
    return {"status": execution.status.value, "steps": steps, "total_steps": len(plan.commands),
            "final_state": state}
