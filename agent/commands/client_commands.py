"""Client commands for a running daemon: send, events, status, estop, health, history, ..."""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

EXIT_DONE = 0
EXIT_NOT_DONE = 1
EXIT_NO_DAEMON = 2
EXIT_REFUSED = 3

_SOCKET_HELP = (
    "daemon socket (default: $NRTRANS_SOCKET, else api.socket in the config file, "
    "else nrtrans.sock in the runtime dir, as `nrtrans serve` picks it)"
)
_CONFIG_HELP = "the daemon's config file, read for api.socket (default: $NRTRANS_CONFIG)"


def register(subparsers: Any) -> None:
    def add(name: str, help: str, description: str, func: Any) -> argparse.ArgumentParser:
        parser = subparsers.add_parser(name, help=help, description=description)
        parser.add_argument("--socket", metavar="PATH", help=_SOCKET_HELP)
        parser.add_argument("--config", metavar="FILE", help=_CONFIG_HELP)
        parser.add_argument("--json", action="store_true", help="print the raw JSON frames")
        parser.set_defaults(func=func)
        return parser

    send = add(
        "send",
        "send a task to the daemon and follow it until it ends",
        "Submit a task (plain words, or an RSL program with --rsl) to the daemon and print "
        "its events until it ends. Exit status: 0 when the task is done, 1 when it failed, "
        "was rejected or cancelled, 2 when the daemon cannot be reached, 3 when it refused "
        "the task (busy, emergency stop latched, too long). Ctrl-C cancels the task.",
        _send,
    )
    send.add_argument("task", help='what the robot should do, e.g. "move forward one meter then turn left"')
    send.add_argument("--rsl", action="store_true", help="TASK is an RSL program to verify and run as is")
    send.add_argument("--no-wait", action="store_true", help="print the task id and return at once")

    events = add(
        "events",
        "print the daemon's events as they happen",
        "Stream events (all tasks, or one with --task) until Ctrl-C.",
        _events,
    )
    events.add_argument("--task", metavar="ID", help="only this task's events, ending with its last one")

    status = add(
        "status",
        "show the daemon's state, or one task's record",
        "Show the daemon's state (idle, busy, estopped, queue) or, with ID, one task's record.",
        _status,
    )
    status.add_argument("task", nargs="?", metavar="ID", help="a task id from `nrtrans send` or `history`")

    confirm = add(
        "confirm",
        "answer the daemon's question about a task",
        "Let a task the daemon asked about (a `confirm` event) run, or cancel it. "
        "The audit log records your uid as the one who answered.",
        _confirm,
    )
    confirm.add_argument("task", metavar="ID")
    confirm.add_argument("answer", choices=("yes", "no"))
    cancel = add("cancel", "cancel one task", "Cancel a queued or running task; a running one stops mid-step.", _cancel)
    cancel.add_argument("task", metavar="ID")

    estop = add(
        "estop",
        "emergency stop: stop the robot and refuse tasks until reset",
        "Stop the robot now, cancel every task, and latch: new tasks are refused until `nrtrans reset`.",
        _estop,
    )
    estop.add_argument("--reason", help="recorded in the event and the daemon status")

    add(
        "reset",
        "release a latched emergency stop",
        "Release the emergency stop latch so tasks are accepted again. Check the robot is safe first.",
        _reset,
    )
    add(
        "health",
        "check whether the daemon and its parts are well",
        "Show the health of each part (worker, translator, robot, audit log, speech). Exit 0 when healthy, 1 when not.",
        _health,
    )
    history = add(
        "history",
        "show recent tasks from the audit log",
        "Show the most recent tasks from the daemon's audit log, newest last, including "
        "tasks from before a restart (in-flight ones marked interrupted).",
        _history,
    )
    history.add_argument("-n", "--limit", type=int, default=20, help="how many tasks (default 20, max 1000)")
    history.add_argument(
        "--audit",
        metavar="FILE",
        help="read this audit log file directly (e.g. while the daemon is stopped) instead of asking the daemon",
    )
    add(
        "listen",
        "push-to-talk: start listening for a spoken task now",
        "Tell the daemon to listen now, without the wake word.",
        _listen,
    )


def _connect(args: argparse.Namespace) -> Any:
    from agent.client import Client

    return Client.connect(args.socket, timeout=None, config_file=args.config)


def _call(args: argparse.Namespace, action: Any) -> int:
    from agent.client import ClientError, RequestFailed

    try:
        with _connect(args) as client:
            return int(action(client))
    except RequestFailed as exc:
        print(f"nrtrans {args.command}: error: {exc.message}", file=sys.stderr)
        if exc.help:
            print(f"  = help: {exc.help}", file=sys.stderr)
        return EXIT_REFUSED
    except ClientError as exc:
        print(f"nrtrans {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_NO_DAEMON


def _send(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        fields = {"rsl": args.task} if args.rsl else {"text": args.task}
        task = client.submit(**fields, follow=not args.no_wait)
        if args.no_wait:
            print(task)
            return EXIT_DONE
        try:
            for event in client.follow(task):
                _print_event(event, args.json)
                if event["event"] == "done":
                    return EXIT_DONE
                if event["event"] == "confirm":
                    _answer(client, task, event["timeout_s"])
        except KeyboardInterrupt:
            client.cancel(task)
            print(f"nrtrans send: cancelled task {task}", file=sys.stderr)
            return 130
        return EXIT_NOT_DONE

    return _call(args, action)


def _answer(client: Any, task: str, timeout_s: float) -> None:
    """Put the daemon's question to the person at a terminal; elsewhere say how to answer it."""
    if not sys.stdin.isatty():
        print(f"nrtrans send: the daemon asks before moving; answer within {timeout_s:g} s with "
              f"`nrtrans confirm {task} yes` (or `no`)", file=sys.stderr)
        return
    from agent.client import RequestFailed

    reply = input(f"Run it? [y/N] (within {timeout_s:g} s) ").strip().lower()
    try:
        client.confirm(task, reply in ("y", "yes"))
    except RequestFailed as exc:
        print(f"nrtrans send: {exc.message}", file=sys.stderr)


def _confirm(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        client.confirm(args.task, args.answer == "yes")
        print(f"{args.task}: {'accepted' if args.answer == 'yes' else 'declined'}")
        return 0

    return _call(args, action)


def _events(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        client.subscribe(args.task)
        stream = client.follow(args.task) if args.task else client.events()
        try:
            for event in stream:
                _print_event(event, args.json)
        except KeyboardInterrupt:
            return 0
        return 0

    return _call(args, action)


def _status(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        data = client.status(args.task)
        if args.json:
            print(json.dumps(data, indent=2))
        elif args.task:
            print(_describe_record(data, detailed=True))
        else:
            line = f"{data['state']}: {data['queued']} queued (limit {data['queue_size']}), backend {data['backend']}"
            if data.get("current"):
                line += f", running {data['current']}"
            if data.get("estop"):
                line += f"\nEMERGENCY STOP latched: {data['estop']} (release with `nrtrans reset`)"
            print(line)
        return 0

    return _call(args, action)


def _cancel(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        reply = client.cancel(args.task)
        print(json.dumps(reply) if args.json else f"{reply['task']}: {reply['state']}")
        return 0

    return _call(args, action)


def _estop(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        client.estop(args.reason)
        print("emergency stop latched: the robot is stopped; `nrtrans reset` releases it")
        return 0

    return _call(args, action)


def _reset(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        latched = client.status().get("estop")
        client.reset()
        if latched:
            print(f"emergency stop released ({latched}): tasks are accepted again")
        else:
            print("no emergency stop was latched: nothing to release; tasks are accepted")
        return 0

    return _call(args, action)


def _health(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        reply = client.health()
        if args.json:
            print(json.dumps(reply, indent=2))
        else:
            print(_health_headline(reply))
            for name, part in reply["components"].items():
                mark = "ok " if part.get("ok") else "off" if part.get("enabled") is False else "BAD"
                print(f"  {name:<11} {mark}  {part.get('detail', '')}")
                if part.get("help"):
                    print(f"  {'':<11}      = help: {part['help']}")
        return 0 if reply["healthy"] else 1

    return _call(args, action)


def _health_headline(reply: dict[str, Any]) -> str:
    bad = [
        name for name, part in reply["components"].items() if not part.get("ok") and part.get("enabled") is not False
    ]
    if not reply["healthy"]:
        return f"NOT healthy: {', '.join(bad)} {'is' if len(bad) == 1 else 'are'} not working"
    if bad:
        return f"working, but {', '.join(bad)} {'needs' if len(bad) == 1 else 'need'} attention"
    return "healthy"


def _history(args: argparse.Namespace) -> int:
    limit = max(1, min(args.limit, 1000))

    def action(client: Any) -> int:
        return _show_history(client.history(limit), args.json)

    if args.audit:
        from pathlib import Path

        from agent.daemon.audit import AuditLog

        path = Path(args.audit)
        if not path.is_file():
            print(f"nrtrans history: error: no audit log at {path}", file=sys.stderr)
            return EXIT_NO_DAEMON
        return _show_history(AuditLog(path).recent(limit), args.json)
    return _call(args, action)


def _show_history(records: list[dict[str, Any]], raw: bool) -> int:
    if raw:
        print(json.dumps(records, indent=2))
    elif not records:
        print("no tasks recorded yet")
    else:
        for record in records:
            print(_describe_record(record, detailed=False))
    return 0


def _listen(args: argparse.Namespace) -> int:
    def action(client: Any) -> int:
        client.listen()
        print("listening: say the task now")
        return 0

    return _call(args, action)


def _describe_record(record: dict[str, Any], *, detailed: bool) -> str:
    when = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(record.get("created", 0)))
    task = record.get("text") or record.get("rsl") or ""
    head = f"{when}  {record['task']}  {record['state']:<11}  {record.get('source', '?'):<6}  {task!r}"
    if record.get("reason"):
        head += f"\n    reason: {record['reason']}"
    if record.get("program"):
        head += "\n    program: " + record["program"].strip().replace("\n", " ")
    if detailed:
        for attempt in record.get("attempts", []):
            head += f"\n    attempt {attempt['pass']}: {attempt['program'].strip()!r}"
            for diag in attempt.get("diagnostics", []):
                head += f"\n      {diag.get('code', '')} line {diag.get('line')}: {diag.get('message')}"
        for step in record.get("steps", []):
            head += f"\n    step {step['step']}: {step['statement']} -> {step['outcome']['status']}"
            if step["outcome"].get("reason"):
                head += f" ({step['outcome']['reason']})"
        if record.get("timings_ms"):
            head += "\n    timings (ms): " + ", ".join(f"{k}={v}" for k, v in record["timings_ms"].items())
    return head


def _print_event(event: dict[str, Any], raw: bool) -> None:
    from agent.client import describe_event

    print(json.dumps(event) if raw else describe_event(event), flush=True)
