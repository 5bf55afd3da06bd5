"""`health` in words: what is wrong with a part and what to do, never a raw dict."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from agent.daemon.health import describe
from agent.speech import SpeechConfig, SpeechInput


def _components(speech: dict[str, Any], *, estop: str | None = None) -> dict[str, dict[str, Any]]:
    return {
        "worker": {"ok": True},
        "translator": {"ok": True, "warm_s": 1.25, "model": "gemma.gguf"},
        "robot": {"ok": True, "backend": "sim", "state": {"pose": {"x": 0.5, "y": 0.0, "heading": 1.0}}},
        "audit": {"ok": True, "path": "/var/lib/nrtrans/audit.jsonl"},
        "speech": speech,
        "estop": {"ok": estop is None, "latched": estop is not None, "reason": estop},
    }


def test_a_speech_input_without_a_model_says_so_and_what_to_do(tmp_path: Path) -> None:
    speech = SpeechInput(SpeechConfig(model=str(tmp_path / "no-model"), language="ko"), lambda _t: None)
    speech.start()
    try:
        deadline = time.monotonic() + 30
        while speech.health()["state"] != "no_model":
            assert time.monotonic() < deadline, speech.health()
            time.sleep(0.05)
        components = _components({"ok": True, **speech.health()})
    finally:
        speech.stop()
    describe(components, backend="sim", speech_problem="")
    part = components["speech"]
    assert part["detail"].startswith("no speech model: no Vosk model at"), part["detail"]
    assert "{" not in part["detail"] and "Vosk model" in part["help"]


def test_every_part_has_words_and_only_bad_parts_have_help() -> None:
    components = _components({"ok": False}, estop="requested by uid 0 (pid 1)")
    describe(components, backend="sim", speech_problem="disabled in the config ([speech] enabled = false)")
    assert all(isinstance(part["detail"], str) and part["detail"] for part in components.values())
    assert components["robot"]["detail"] == "sim backend, at x 0.50, y 0.00, heading 1.00"
    assert components["speech"]["enabled"] is False and "help" not in components["speech"], "switched off is no fault"
    estop = components["estop"]
    assert "requested by uid 0" in estop["detail"] and "`nrtrans reset`" in estop["help"]
    assert {name for name, part in components.items() if "help" in part} == {"estop"}
