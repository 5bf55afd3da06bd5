"""JSON Schemas for every frame of the socket API, version 1.

These are data, not documentation: the daemon validates each request
against them, the tests validate real replies and events against them, and
docs/api.md embeds them (`render_markdown`), so all three agree.
"""

from __future__ import annotations

import json
from typing import Any

VERSION = 1

_ID = {
    "description": "Any string or integer; echoed in the reply so a client can match them.",
    "type": ["string", "integer"],
}
_TASK_ID = {"type": "string", "pattern": "^[A-Za-z0-9_-]{1,64}$"}


def _request(
    op: str, description: str, properties: dict[str, Any] | None = None, required: tuple[str, ...] = (), **extra: Any
) -> dict[str, Any]:
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": f"request: {op}",
        "description": description,
        "type": "object",
        "properties": {"v": {"const": VERSION}, "op": {"const": op}, "id": _ID, **(properties or {})},
        "required": ["v", "op", *required],
        "additionalProperties": False,
        **extra,
    }


REQUESTS: dict[str, dict[str, Any]] = {
    "submit": _request(
        "submit",
        "Queue one task, either a spoken-style `text` task to translate or an `rsl` program to "
        "verify and run. Replies at once with the task id. With `follow`, this connection also "
        "receives the task's events.",
        {
            "text": {"type": "string", "minLength": 1},
            "rsl": {"type": "string", "minLength": 1},
            "follow": {"type": "boolean", "default": False},
        },
        oneOf=[
            {"required": ["text"], "not": {"required": ["rsl"]}},
            {"required": ["rsl"], "not": {"required": ["text"]}},
        ],
    ),
    "status": _request(
        "status", "The state of one task, or of the daemon when `task` is left out.", {"task": _TASK_ID}
    ),
    "cancel": _request(
        "cancel", "Cancel one task: dropped if queued, stopped mid-step if running.", {"task": _TASK_ID}, ("task",)
    ),
    "confirm": _request(
        "confirm",
        "Answer the question a `confirm` event asked about a task: `accept` true lets its plan run, "
        "false cancels it and nothing moves. The audit log records who answered.",
        {"task": _TASK_ID, "accept": {"type": "boolean"}},
        ("task", "accept"),
    ),
    "estop": _request(
        "estop",
        "Emergency stop: stop the robot now, cancel every task and refuse new ones until `reset`.",
        {"reason": {"type": "string", "maxLength": 200}},
    ),
    "reset": _request("reset", "Release a latched emergency stop."),
    "subscribe": _request(
        "subscribe", "Stream events on this connection: all of them, or one task's.", {"task": _TASK_ID}
    ),
    "listen": _request("listen", "Push-to-talk: start listening for a spoken task now."),
    "health": _request("health", "Whether the service and each of its parts are well."),
    "history": _request(
        "history",
        "The most recent task records from the audit log, newest last.",
        {"limit": {"type": "integer", "minimum": 1, "maximum": 1000, "default": 20}},
    ),
}

_TASK_STATES = [
    "queued", "translating", "confirming", "executing", "done", "failed", "rejected", "cancelled", "interrupted"
]

TASK_RECORD: dict[str, Any] = {
    "type": "object",
    "properties": {
        "task": _TASK_ID,
        "state": {"enum": _TASK_STATES},
        "source": {"enum": ["socket", "voice"]},
        "peer": {"type": ["object", "null"]},
        "text": {"type": ["string", "null"]},
        "rsl": {"type": ["string", "null"]},
        "program": {"type": ["string", "null"]},
        "plan": {"type": ["array", "null"]},
        "attempts": {"type": "array"},
        "steps": {"type": "array"},
        "reason": {"type": "string"},
        "timings_ms": {"type": "object"},
        "created": {"type": "number"},
    },
    "required": ["task", "state", "source", "created"],
}

REPLY: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "reply",
    "description": "The answer to one request. Fields beyond the envelope depend on `op`.",
    "type": "object",
    "properties": {
        "v": {"const": VERSION},
        "type": {"const": "reply"},
        "op": {"enum": sorted(REQUESTS)},
        "id": _ID,
        "ok": {"const": True},
        "task": {"oneOf": [_TASK_ID, TASK_RECORD]},
        "state": {"enum": _TASK_STATES},
        "position": {"type": "integer", "minimum": 0},
        "daemon": {"type": "object"},
        "latched": {"type": "boolean"},
        "accepted": {"type": "boolean"},
        "subscribed": {"type": "boolean"},
        "listening": {"type": "boolean"},
        "healthy": {"type": "boolean"},
        "components": {"type": "object"},
        "tasks": {"type": "array", "items": TASK_RECORD},
    },
    "required": ["v", "type", "op", "ok"],
    "additionalProperties": False,
}

ERROR_CODES = {
    "bad_json": "The frame is not one JSON object in UTF-8.",
    "bad_version": "`v` is missing or not a version this daemon speaks.",
    "unknown_op": "`op` is missing or not a known request.",
    "bad_request": "The request does not match its schema; `message` says which field.",
    "too_long": "The frame or the task is longer than the configured limit.",
    "busy": "The task queue or the client table is full; try again when a task has finished.",
    "estopped": "An emergency stop is latched; send `reset` first.",
    "not_found": "No task with that id is known.",
    "not_waiting": "The task is not waiting for a confirmation (it was answered, timed out or never asked).",
    "forbidden": "This caller's uid/gid is not on the allow-list.",
    "unavailable": "The part the request needs (e.g. speech input) is not running; see `health`.",
    "too_slow": "This client fell too far behind reading its frames and is being disconnected.",
    "shutting_down": "The daemon is stopping and takes no new work.",
    "internal": "A bug in the daemon; the request had no effect. Please report it.",
}

ERROR: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "error",
    "description": "A request that could not be carried out. The connection stays usable "
    "(except after `too_slow` and `forbidden`).",
    "type": "object",
    "properties": {
        "v": {"const": VERSION},
        "type": {"const": "error"},
        "op": {"type": ["string", "null"]},
        "id": {"type": ["string", "integer", "null"]},
        "error": {
            "type": "object",
            "properties": {
                "code": {"enum": sorted(ERROR_CODES)},
                "message": {"type": "string"},
                "help": {"type": "string"},
            },
            "required": ["code", "message"],
            "additionalProperties": False,
        },
    },
    "required": ["v", "type", "error"],
    "additionalProperties": False,
}

_OUTCOME = {
    "type": "object",
    "properties": {"status": {"enum": ["done", "failed", "cancelled"]}, "reason": {"type": "string"}},
    "required": ["status", "reason"],
}

EVENT_FIELDS: dict[str, tuple[str, dict[str, Any]]] = {
    "queued": (
        "A task was accepted.",
        {
            "source": {"enum": ["socket", "voice"]},
            "position": {"type": "integer"},
            "text": {"type": ["string", "null"]},
            "rsl": {"type": ["string", "null"]},
        },
    ),
    "heard": (
        "Speech input produced a transcript; the task it starts follows.",
        {
            "text": {"type": "string"},
            "source": {"type": "string"},
            "started_at": {"type": "number"},
            "ended_at": {"type": "number"},
        },
    ),
    "translating": ("The model is writing a program for the task.", {"text": {"type": "string"}}),
    "attempt": (
        "One program written by the model (or submitted) and its diagnostics.",
        {
            "pass": {"type": "integer", "minimum": 1},
            "program": {"type": "string"},
            "diagnostics": {"type": "array", "items": {"type": "object"}},
        },
    ),
    "verified": (
        "The program compiled; this plan will run (after a `confirm` question, when the policy asks one). "
        "`explanation` says the plan in words; `confidence` (0 to 1, null for a submitted `rsl` "
        "program) is how sure the translation is that the plan is what was meant.",
        {
            "program": {"type": "string"},
            "plan": {"type": "array"},
            "explanation": {"type": "string"},
            "confidence": {"type": ["number", "null"], "minimum": 0, "maximum": 1},
        },
    ),
    "confirm": (
        "The daemon asks before the robot moves (config `translator.confirm`). Nothing moves until a "
        "`confirm` request or a spoken yes/no answers; after `timeout_s` the task is cancelled.",
        {
            "text": {"type": ["string", "null"]},
            "explanation": {"type": "string"},
            "confidence": {"type": ["number", "null"], "minimum": 0, "maximum": 1},
            "reasons": {"type": "array", "items": {"type": "string"}},
            "timeout_s": {"type": "number"},
        },
    ),
    "answered": (
        "The `confirm` question was answered; `by` is `uid N` for a request or `voice`.",
        {"accepted": {"type": "boolean"}, "by": {"type": "string"}},
    ),
    "rejected": (
        "No verified program; nothing moved.",
        {"reason": {"type": "string"}, "diagnostics": {"type": "array"}},
    ),
    "executing": (
        "Step `step` of `total` starts.",
        {
            "step": {"type": "integer", "minimum": 1},
            "total": {"type": "integer", "minimum": 1},
            "statement": {"type": "string"},
        },
    ),
    "step": (
        "Step `step` of `total` ended.",
        {
            "step": {"type": "integer", "minimum": 1},
            "total": {"type": "integer", "minimum": 1},
            "statement": {"type": "string"},
            "outcome": _OUTCOME,
        },
    ),
    "done": ("Every step succeeded.", {"state": {"type": ["object", "null"]}}),
    "failed": (
        "A step failed or the task could not run.",
        {"reason": {"type": "string"}, "state": {"type": ["object", "null"]}},
    ),
    "cancelled": (
        "Cancelled, by `cancel`, `estop` or shutdown.",
        {"reason": {"type": "string"}, "state": {"type": ["object", "null"]}},
    ),
    "estop": ("An emergency stop latched.", {"reason": {"type": "string"}}),
    "reset": ("The emergency stop was released.", {}),
    "speech": (
        "Speech input changed state (listening, wake word, unavailable, ...).",
        {"state": {"type": "string"}, "detail": {"type": "object"}},
    ),
}

EVENT: dict[str, Any] = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "event",
    "description": "Sent to subscribed connections as things happen. `task` is null for events "
    "about the daemon as a whole (estop, reset, speech).",
    "type": "object",
    "properties": {
        "v": {"const": VERSION},
        "type": {"const": "event"},
        "event": {"enum": sorted(EVENT_FIELDS)},
        "task": {"oneOf": [_TASK_ID, {"type": "null"}]},
        "ts": {"type": "number", "description": "Unix time in seconds."},
        "seq": {"type": "integer", "minimum": 1, "description": "Increases by one per event."},
    },
    "required": ["v", "type", "event", "task", "ts", "seq"],
    "allOf": [
        {
            "if": {"properties": {"event": {"const": name}}},
            "then": {"properties": props, "required": [k for k in props if k != "state"]},
        }
        for name, (_doc, props) in EVENT_FIELDS.items()
    ],
}


def render_markdown() -> str:
    """The schema part of docs/api.md."""
    parts = ["## Schemas", "", "<!-- Generated from agent/daemon/schemas.py by `nrtrans serve --api-doc`. -->", ""]
    for op, schema in REQUESTS.items():
        parts += [
            f"### request `{op}`",
            "",
            schema["description"],
            "",
            "```json",
            json.dumps(schema, indent=2),
            "```",
            "",
        ]
    for title, schema in (("reply", REPLY), ("error", ERROR), ("event", EVENT)):
        parts += [f"### {title}", "", schema["description"], "", "```json", json.dumps(schema, indent=2), "```", ""]
    parts += ["### error codes", "", "| code | meaning |", "|---|---|"]
    parts += [f"| `{code}` | {meaning} |" for code, meaning in ERROR_CODES.items()]
    parts += ["", "### events", "", "| event | meaning |", "|---|---|"]
    parts += [f"| `{name}` | {doc} |" for name, (doc, _props) in EVENT_FIELDS.items()]
    return "\n".join(parts) + "\n"
