"""Request decoding never raises, and every frame matches its published schema."""

from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from jsonschema import Draft202012Validator

from agent.daemon.protocol import ProtocolError, Request, decode_request, encode
from agent.daemon.schemas import ERROR, EVENT, REPLY, REQUESTS, render_markdown

ROOT = Path(__file__).resolve().parents[2]
ERRORS = Draft202012Validator(ERROR)

json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=30),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=12,
)
request_like = st.fixed_dictionaries(
    {},
    optional={
        "v": st.sampled_from([1, 2, "1", None, True]),
        "op": st.sampled_from([*REQUESTS, "exec", "", 7]),
        "id": json_values,
        "text": json_values,
        "rsl": json_values,
        "task": json_values,
        "follow": json_values,
        "limit": json_values,
        "reason": json_values,
        "extra": json_values,
    },
)


def _check(decoded: Request | ProtocolError) -> None:
    if isinstance(decoded, ProtocolError):
        ERRORS.validate(decoded.frame())
        assert len(decoded.message) < 400, "error messages never echo a whole frame"
    else:
        Draft202012Validator(REQUESTS[decoded.op]).validate(decoded.body)


@settings(max_examples=600, deadline=None)
@given(st.binary(max_size=300))
def test_arbitrary_bytes_never_crash_the_decoder(data: bytes) -> None:
    _check(decode_request(data, max_task_chars=100))


@settings(max_examples=600, deadline=None)
@given(request_like)
def test_request_shaped_objects_are_accepted_only_when_valid(body: dict) -> None:
    decoded = decode_request(encode(body), max_task_chars=100)
    _check(decoded)
    if isinstance(decoded, Request):
        assert body.get("v") == 1 and body.get("op") in REQUESTS


def test_well_formed_requests_decode() -> None:
    for line in (
        '{"v":1,"op":"submit","text":"go forward"}',
        '{"v":1,"op":"submit","rsl":"forward 1;"}',
        '{"v":1,"op":"status"}',
        '{"v":1,"op":"cancel","task":"abc123"}',
        '{"v":1,"op":"history","limit":5,"id":"x"}',
        '{"v":1,"op":"estop","reason":"test"}',
    ):
        assert isinstance(decode_request(line.encode(), max_task_chars=100), Request), line


def test_bad_requests_get_the_right_code() -> None:
    cases = {
        b"not json": "bad_json",
        b"[]": "bad_json",
        b'\xff{"v":1}': "bad_json",
        b'{"op":"health"}': "bad_version",
        b'{"v":2,"op":"health"}': "bad_version",
        b'{"v":1,"op":"exec","cmd":"rm -rf /"}': "unknown_op",
        b'{"v":1,"op":"submit","text":"a","rsl":"b"}': "bad_request",
        b'{"v":1,"op":"submit","text":"go","path":"/etc/passwd"}': "bad_request",
        b'{"v":1,"op":"cancel","task":"../../x"}': "bad_request",
        b'{"v":1,"op":"submit","text":"' + b"a" * 101 + b'"}': "too_long",
    }
    for line, code in cases.items():
        decoded = decode_request(line, max_task_chars=100)
        assert isinstance(decoded, ProtocolError) and decoded.code == code, (line, decoded)


def test_deeply_nested_json_is_an_error_not_a_crash() -> None:
    decoded = decode_request(b"[" * 100000 + b"]" * 100000, max_task_chars=100)
    assert isinstance(decoded, ProtocolError) and decoded.code == "bad_json"


def test_schemas_are_valid_and_documented() -> None:
    for schema in (*REQUESTS.values(), REPLY, ERROR, EVENT):
        Draft202012Validator.check_schema(schema)
    api_md = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    assert api_md.endswith(render_markdown()), (
        "docs/api.md is stale: replace its schema part with `nrtrans serve --api-doc`"
    )
    assert json.dumps(REQUESTS["submit"], indent=2) in api_md


def test_a_protocol_error_passes_through_a_with_block_unchanged() -> None:
    """Python sets `__traceback__` on an exception leaving a generator context manager; a frozen one broke."""
    @contextmanager
    def guarded() -> Iterator[None]:
        yield

    with pytest.raises(ProtocolError) as raised, guarded():
        raise ProtocolError("busy", "the task queue is full")
    assert raised.value.code == "busy"
