"""Frames of the socket API: decoding requests, encoding replies, errors and events.

A frame is one JSON object on one line. Decoding never raises on bad input:
it returns a `ProtocolError` that becomes an error reply, so one bad frame
never costs a client its connection.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from jsonschema import Draft202012Validator
from jsonschema.exceptions import best_match

from agent.daemon.schemas import ERROR_CODES, REQUESTS, VERSION

_VALIDATORS = {op: Draft202012Validator(schema) for op, schema in REQUESTS.items()}


@dataclass(frozen=True)
class Request:
    op: str
    body: dict[str, Any]

    @property
    def id(self) -> str | int | None:
        return self.body.get("id")


# Not frozen: Python writes `__traceback__` on an exception as it leaves a
# `with` block, and a frozen one turns into FrozenInstanceError there. No
# `eq`, so it stays hashable by identity like any exception.
@dataclass(eq=False)
class ProtocolError(Exception):
    code: str
    message: str
    help: str = ""
    op: str | None = None
    id: str | int | None = None

    def frame(self) -> dict[str, Any]:
        return error_frame(self.code, self.message, self.help, op=self.op, request_id=self.id)


def decode_request(line: bytes, *, max_task_chars: int) -> Request | ProtocolError:
    try:
        data = json.loads(line.decode("utf-8"))
    except UnicodeDecodeError:
        return ProtocolError("bad_json", "the frame is not valid UTF-8", "send one JSON object per line, UTF-8 encoded")
    except (ValueError, RecursionError) as exc:
        return ProtocolError(
            "bad_json",
            f"the frame is not valid JSON: {exc}",
            'send one JSON object per line, e.g. {"v": 1, "op": "health"}',
        )
    if not isinstance(data, dict):
        return ProtocolError(
            "bad_json",
            f"the frame is a JSON {type(data).__name__}, not an object",
            'send one JSON object per line, e.g. {"v": 1, "op": "health"}',
        )
    request_id = data.get("id")
    if isinstance(request_id, bool) or not isinstance(request_id, str | int | None):
        request_id = None
    op = data.get("op")
    op_name = op if isinstance(op, str) and op in REQUESTS else None
    where = _lone_surrogate(data)
    if where is not None:
        # Such a string cannot be written back as UTF-8: not in a reply, an event or the audit log.
        return ProtocolError(
            "bad_request",
            f"{op_name or 'the request'}: {_shorten(where, 100)}: "
            "the string holds a lone UTF-16 surrogate (\\ud800-\\udfff)",
            "send valid Unicode: a character outside the BMP as a surrogate pair or as plain UTF-8",
            op=op_name,
            id=request_id if not isinstance(request_id, str) or _is_text(request_id) else None,
        )
    if data.get("v") != VERSION or isinstance(data.get("v"), bool):
        return ProtocolError(
            "bad_version",
            f"unsupported protocol version {data.get('v')!r}",
            f'this daemon speaks version {VERSION}: add "v": {VERSION} to the frame',
            op=op_name,
            id=request_id,
        )
    if op_name is None:
        return ProtocolError(
            "unknown_op", f"unknown request {op!r}", f"`op` must be one of {', '.join(sorted(REQUESTS))}", id=request_id
        )
    error = best_match(_VALIDATORS[op_name].iter_errors(data))
    if error is not None:
        where = "/".join(str(p) for p in error.absolute_path) or "the request"
        # jsonschema quotes the offending value, which may be the whole (large) frame.
        message = "give exactly one of `text` and `rsl`" if error.validator == "oneOf" else _shorten(error.message)
        return ProtocolError(
            "bad_request",
            f"{op_name}: {where}: {message}",
            "see docs/api.md for the fields of each request",
            op=op_name,
            id=request_id,
        )
    for key in ("text", "rsl"):
        value = data.get(key)
        if isinstance(value, str) and len(value) > max_task_chars:
            return ProtocolError(
                "too_long",
                f"the {key} is {len(value)} characters; the limit is {max_task_chars}",
                "split the task into shorter ones",
                op=op_name,
                id=request_id,
            )
    return Request(op_name, data)


def _lone_surrogate(data: dict[str, Any]) -> str | None:
    """The path of the first key or string value that is not valid Unicode text, or None."""
    stack: list[tuple[str, Any]] = [("", data)]
    while stack:
        path, value = stack.pop()
        if isinstance(value, str):
            if not _is_text(value):
                return path or "the request"
        elif isinstance(value, dict):
            for key, item in value.items():
                if not _is_text(key):
                    return f"{path}/key {key!a}" if path else f"key {key!a}"
                stack.append((f"{path}/{key}" if path else key, item))
        elif isinstance(value, list):
            stack.extend((f"{path}/{index}", item) for index, item in enumerate(value))
    return None


def _is_text(value: str) -> bool:
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def _shorten(text: str, limit: int = 200) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def encode(frame: dict[str, Any]) -> bytes:
    return json.dumps(frame, separators=(",", ":"), ensure_ascii=False).encode("utf-8") + b"\n"


def reply_frame(request: Request, **fields: Any) -> dict[str, Any]:
    frame: dict[str, Any] = {"v": VERSION, "type": "reply", "op": request.op, "ok": True}
    if request.id is not None:
        frame["id"] = request.id
    frame.update(fields)
    return frame


def error_frame(
    code: str, message: str, help: str = "", *, op: str | None = None, request_id: str | int | None = None
) -> dict[str, Any]:
    assert code in ERROR_CODES, code
    error: dict[str, Any] = {"code": code, "message": message}
    if help:
        error["help"] = help
    return {"v": VERSION, "type": "error", "op": op, "id": request_id, "error": error}
