"""A small client for the nrtrans daemon's socket API.

    with Client.connect() as client:
        task = client.submit(text="move forward one meter", follow=True)
        for event in client.events():
            print(event["event"])
            if event["event"] in TERMINAL_EVENTS and event["task"] == task:
                break

Replies and events share one connection; `request` returns the reply to
its own request and keeps any events that arrived first for `events`.
"""

from __future__ import annotations

import itertools
import json
import os
import socket
from collections import deque
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from agent.daemon.config import ConfigError, config_path_from_env, load_config

VERSION = 1
TERMINAL_EVENTS = frozenset({"done", "failed", "cancelled", "rejected"})


class ClientError(Exception):
    """The daemon could not be reached or the connection broke."""


class RequestFailed(ClientError):
    """The daemon answered a request with an error frame."""

    def __init__(self, frame: dict[str, Any]) -> None:
        error = frame.get("error", {})
        self.code: str = error.get("code", "unknown")
        self.message: str = error.get("message", "")
        self.help: str = error.get("help", "")
        self.frame = frame
        super().__init__(f"{self.code}: {self.message}")


def find_socket(flag: str | Path | None = None, config_file: str | Path | None = None) -> Path:
    """Where the daemon listens; `nrtrans serve` and every client command look in this order.

    1. the `--socket PATH` flag;
    2. `$NRTRANS_SOCKET`;
    3. `api.socket` in the config file (`--config FILE`, else `$NRTRANS_CONFIG`);
    4. the default, `nrtrans.sock` in the runtime directory (`$RUNTIME_DIRECTORY`, else
       `$XDG_RUNTIME_DIR/nrtrans`, else `/run/nrtrans`).
    """
    if flag:
        return Path(flag).expanduser()
    if os.environ.get("NRTRANS_SOCKET"):
        return Path(os.environ["NRTRANS_SOCKET"]).expanduser()
    try:
        config = load_config(config_path_from_env(str(config_file) if config_file else None))
    except ConfigError as exc:
        raise ClientError(f"cannot tell where the daemon listens: {exc}") from None
    return config.socket_path()


class Client:
    def __init__(self, sock: socket.socket, path: Path) -> None:
        self._sock = sock
        self._file = sock.makefile("rb")
        self.path = path
        self._ids = itertools.count(1)
        self._pending: deque[dict[str, Any]] = deque()

    @classmethod
    def connect(
        cls, path: str | Path | None = None, *, timeout: float | None = 10.0, config_file: str | Path | None = None
    ) -> Client:
        """Connect to the socket at `path`, or the one `find_socket` names."""
        socket_path = find_socket(path, config_file)
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(timeout)
        try:
            sock.connect(str(socket_path))
        except FileNotFoundError:
            sock.close()
            raise ClientError(
                f"no daemon socket at {socket_path}\n"
                "  = help: start the daemon with `nrtrans serve`, or point at its socket with --socket PATH, "
                "$NRTRANS_SOCKET or api.socket in --config FILE ($NRTRANS_CONFIG), in that order"
            ) from None
        except PermissionError:
            sock.close()
            raise ClientError(
                f"permission denied on {socket_path}\n  = help: the socket is mode 0660; join the daemon's group"
            ) from None
        except OSError as exc:
            sock.close()
            raise ClientError(
                f"cannot connect to {socket_path}: {exc.strerror or exc}\n  = help: is `nrtrans serve` running?"
            ) from None
        return cls(sock, socket_path)

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._file.close()
        self._sock.close()

    def settimeout(self, timeout: float | None) -> None:
        self._sock.settimeout(timeout)

    # -- requests -------------------------------------------------------------------------------

    def request(self, op: str, **fields: Any) -> dict[str, Any]:
        """Send one request and return its reply; raises `RequestFailed` on an error frame."""
        request_id = next(self._ids)
        self.send_frame({"v": VERSION, "op": op, "id": request_id, **fields})
        while True:
            frame = self.read_frame()
            if frame.get("type") == "event":
                self._pending.append(frame)
                continue
            if frame.get("id") not in (request_id, None):
                continue
            if frame.get("type") == "error":
                raise RequestFailed(frame)
            return frame

    def submit(self, *, text: str | None = None, rsl: str | None = None, follow: bool = False) -> str:
        fields: dict[str, Any] = {"text": text} if text is not None else {"rsl": rsl}
        if follow:
            fields["follow"] = True
        return str(self.request("submit", **fields)["task"])

    def status(self, task: str | None = None) -> dict[str, Any]:
        reply = self.request("status", **({"task": task} if task else {}))
        return reply["task"] if task else reply["daemon"]

    def cancel(self, task: str) -> dict[str, Any]:
        return self.request("cancel", task=task)

    def confirm(self, task: str, accept: bool) -> dict[str, Any]:
        """Answer a `confirm` question: let the plan run, or cancel it."""
        return self.request("confirm", task=task, accept=accept)

    def estop(self, reason: str | None = None) -> dict[str, Any]:
        return self.request("estop", **({"reason": reason} if reason else {}))

    def reset(self) -> dict[str, Any]:
        return self.request("reset")

    def subscribe(self, task: str | None = None) -> None:
        self.request("subscribe", **({"task": task} if task else {}))

    def listen(self) -> dict[str, Any]:
        return self.request("listen")

    def health(self) -> dict[str, Any]:
        return self.request("health")

    def history(self, limit: int = 20) -> list[dict[str, Any]]:
        return list(self.request("history", limit=limit)["tasks"])

    # -- frames ---------------------------------------------------------------------------------

    def events(self) -> Iterator[dict[str, Any]]:
        """Events as they arrive (after `subscribe` or `submit(follow=True)`), forever."""
        while True:
            if self._pending:
                yield self._pending.popleft()
                continue
            frame = self.read_frame()
            if frame.get("type") == "event":
                yield frame

    def follow(self, task: str) -> Iterator[dict[str, Any]]:
        """One task's events, ending with its terminal event."""
        for event in self.events():
            if event.get("task") != task:
                continue
            yield event
            if event["event"] in TERMINAL_EVENTS:
                return

    def send_frame(self, frame: dict[str, Any]) -> None:
        self.send_raw(json.dumps(frame).encode("utf-8") + b"\n")

    def send_raw(self, data: bytes) -> None:
        try:
            self._sock.sendall(data)
        except OSError as exc:
            raise ClientError(f"lost the connection to the daemon: {exc}") from exc

    def read_frame(self) -> dict[str, Any]:
        try:
            line = self._file.readline()
        except TimeoutError:
            raise
        except OSError as exc:
            raise ClientError(f"lost the connection to the daemon: {exc}") from exc
        if not line:
            raise ClientError("the daemon closed the connection")
        frame = json.loads(line)
        if not isinstance(frame, dict):
            raise ClientError(f"the daemon sent a frame that is not an object: {line[:80]!r}")
        return frame


def describe_event(event: dict[str, Any]) -> str:
    """One human-readable line for an event frame (what `nrtrans send` and `events` print)."""
    name = event["event"]
    prefix = f"[{event['task']}]" if event.get("task") else "[daemon]"
    if name == "queued":
        ahead = event["position"]
        detail = "next in line" if ahead == 0 else f"behind {ahead} other task{'s' if ahead > 1 else ''}"
    elif name in ("heard", "translating"):
        detail = repr(event["text"])
    elif name == "attempt":
        errors = event["diagnostics"]
        verdict = (
            "ok"
            if not errors
            else f"{len(errors)} error(s): " + "; ".join(f"line {d.get('line')}: {d.get('message')}" for d in errors)
        )
        detail = f"{event['pass']}: {event['program'].strip()!r} ({verdict})"
    elif name == "verified":
        detail = event["program"].strip().replace("\n", " ")
        if event.get("explanation"):
            detail += f" -> {event['explanation']}"
    elif name == "confirm":
        sure = "" if event.get("confidence") is None else f" (confidence {event['confidence']:.2f})"
        detail = f"should I {event['explanation']}?{sure}"
        if event.get("reasons"):
            detail += " Unsure because " + "; ".join(event["reasons"])
    elif name == "answered":
        detail = f"{'accepted' if event['accepted'] else 'declined'} by {event['by']}"
    elif name == "executing":
        detail = f"step {event['step']}/{event['total']}: {event['statement']}"
    elif name == "step":
        outcome = event["outcome"]
        detail = f"{event['step']}/{event['total']} {outcome['status']}"
        if outcome.get("reason"):
            detail += f" ({outcome['reason']})"
    elif name == "done":
        pose = (event.get("state") or {}).get("pose")
        detail = (
            f"pose x={_number(pose['x'])} y={_number(pose['y'])} heading={_number(pose['heading'])}" if pose else ""
        )
    elif name == "speech":
        detail = str(event.get("state", ""))
    else:
        detail = str(event.get("reason", ""))
    return f"{prefix} {name} {detail}".rstrip()


def _number(value: float) -> str:
    """Two decimals, without the "-0.00" of a value that rounds to zero from below."""
    text = f"{value:.2f}"
    return "0.00" if text == "-0.00" else text
