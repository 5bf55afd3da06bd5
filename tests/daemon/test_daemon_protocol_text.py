"""Lone surrogates (`"\\ud800"` in JSON) are refused at the decoder, so every answer can be encoded."""

from __future__ import annotations

import json

from hypothesis import given, settings
from hypothesis import strategies as st

from agent.daemon.protocol import ProtocolError, Request, decode_request, encode
from agent.daemon.schemas import REQUESTS

_TEXTS = st.text(st.sampled_from(["a", " ", ";", "1", "é", "\U0001f600", "\ud800", "\udfff", "\x00"]), max_size=12)
_VALUES = st.recursive(
    _TEXTS | st.integers(-3, 3) | st.none(),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(_TEXTS, inner, max_size=3),
    max_leaves=8,
)
_FRAMES = st.builds(
    lambda op, fields: {"v": 1, "op": op, **fields},
    st.sampled_from([*REQUESTS, "bogus", "\ud800"]),
    st.dictionaries(st.sampled_from(["id", "text", "rsl", "task", "reason", "limit", "\udc00"]), _VALUES, max_size=3),
)


def _has_surrogate(value: object) -> bool:
    return any(0xD800 <= ord(c) <= 0xDFFF for c in json.dumps(value, ensure_ascii=False))


@settings(max_examples=600, deadline=None)
@given(_FRAMES)
def test_every_answer_to_a_decoded_frame_can_be_encoded(frame: dict) -> None:
    decoded = decode_request(json.dumps(frame).encode("ascii"), max_task_chars=100)
    if isinstance(decoded, ProtocolError):
        encode(decoded.frame())
    else:
        assert not _has_surrogate(decoded.body), "a request that reaches the service holds only text"
        encode({"echo": decoded.body})


def test_the_refusal_names_the_field_and_keeps_a_usable_id() -> None:
    for frame, where, request_id in [
        ({"v": 1, "op": "submit", "text": "go \ud800", "id": 4}, "submit: text:", 4),
        ({"v": 1, "op": "submit", "rsl": "x;", "id": "\udfff"}, "submit: id:", None),
        ({"v": 1, "op": "submit", "text": "\ud800", "id": "\ud800"}, "submit: ", None),
        ({"v": 1, "op": "estop", "reason": "\udc00"}, "estop: reason:", None),
        ({"v": 1, "op": "health", "x": [{"y": "\ud83d"}]}, "health: x/0/y:", None),
    ]:
        decoded = decode_request(json.dumps(frame).encode("ascii"), max_task_chars=100)
        assert isinstance(decoded, ProtocolError) and decoded.code == "bad_request", decoded
        assert decoded.message.startswith(where) and "surrogate" in decoded.message, decoded.message
        assert decoded.id == request_id
    paired = decode_request(b'{"v":1,"op":"submit","text":"smile \\ud83d\\ude00"}', max_task_chars=100)
    assert isinstance(paired, Request) and paired.body["text"] == "smile \U0001f600", "a surrogate pair is text"
