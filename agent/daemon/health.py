"""Words for `health`: each part says what state it is in and, when it is not well, what to do.

The components keep their data fields (for scripts); this adds `detail`, one
sentence a person can read, and `help` to every part that is not ok.
"""

from __future__ import annotations

from typing import Any

_SPEECH_DOCS = "see docs/speech.md"


def describe(components: dict[str, dict[str, Any]], *, backend: str, speech_problem: str) -> None:
    """Fill in `detail` (and `help` where a part is not ok) of each component, in place."""
    worker = components["worker"]
    if worker["ok"]:
        worker["detail"] = "running tasks"
    else:
        worker["detail"] = f"the task worker has stopped: {worker.get('detail') or 'no reason was recorded'}"
        worker["help"] = "restart the daemon (`systemctl restart nrtrans`); the journal says why it stopped"

    translator = components["translator"]
    if translator["ok"]:
        warm = translator.get("warm_s")
        translator["detail"] = f"{translator['model']}, " + (
            f"warmed up in {warm:.1f} s" if warm is not None else "not warmed up (the first task loads it)"
        )
    else:
        translator["detail"] = "no translation model is loaded"
        translator["help"] = "check translator.model and translator.adapter in the config, then restart the daemon"

    robot = components["robot"]
    if robot["ok"]:
        pose = (robot.get("state") or {}).get("pose") or {}
        where = ", ".join(f"{key} {pose[key]:.2f}" for key in ("x", "y", "heading") if key in pose)
        robot["detail"] = f"{backend} backend" + (f", at {where}" if where else "")
    else:
        robot["detail"] = robot.get("detail") or f"the {backend} backend does not answer"
        robot["help"] = (
            "check that the robot's ROS 2 nodes run and share ROS_DOMAIN_ID with the daemon (docs/ros2.md)"
            if backend == "ros2"
            else "restart the daemon; the journal says why the simulator stopped"
        )

    audit = components["audit"]
    if audit["ok"]:
        audit["detail"] = f"writing {audit['path']}"
    else:
        audit["detail"] = f"the audit log {audit['path']} is not open, so nothing may move"
        audit["help"] = "make the state directory writable (or set --state-dir), then restart the daemon"

    _describe_speech(components["speech"], speech_problem)

    estop = components["estop"]
    if estop["latched"]:
        estop["detail"] = (
            f"an emergency stop is latched ({estop.get('reason') or 'no reason given'}): "
            "the robot stays still and new tasks are refused"
        )
        estop["help"] = "check that the robot and the people near it are safe, then run `nrtrans reset`"
    else:
        estop["detail"] = "not latched"


def _describe_speech(speech: dict[str, Any], problem: str) -> None:
    if "state" not in speech:
        # The speech input never started: switched off, or its settings are wrong.
        speech["detail"] = f"speech input is off: {problem}"
        if "disabled in the config" in problem:
            speech["enabled"] = False
        else:
            speech["help"] = f"fix [speech.options] in the config ({_SPEECH_DOCS}); text tasks work meanwhile"
        return
    state = speech["state"]
    model = speech.get("model") or {}
    device = speech.get("audio_device") or {}
    if state == "no_model":
        speech["detail"] = f"no speech model: {model.get('error') or 'none found'}"
        speech["help"] = f"install a Vosk model for the robot's language or set [speech.options] model; {_SPEECH_DOCS}"
    elif state == "no_device":
        speech["detail"] = f"no microphone: {device.get('error') or 'no input device found'}"
        speech["help"] = f"plug in a microphone or set [speech.options] device ({_SPEECH_DOCS}); retrying meanwhile"
    elif state == "waiting_for_wake_word":
        words = ", ".join(repr(w) for w in speech.get("wake_words") or ()) or "the wake word"
        speech["detail"] = f"waiting for {words} on {device.get('name') or 'the default microphone'}"
    elif state == "push_to_talk_only":
        speech["detail"] = "no wake word: listening only after `nrtrans listen`"
    elif state == "listening":
        speech["detail"] = "listening to a spoken task now"
    elif state == "starting":
        speech["detail"] = "starting: loading the speech model"
    else:
        speech["detail"] = f"speech input is {state.replace('_', ' ')}"
    if not speech.get("ok") and "help" not in speech:
        speech["help"] = f"restart the daemon if it stays like this ({_SPEECH_DOCS})"
