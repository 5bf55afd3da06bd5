"""Connects the speech input (agent.speech) to the service, if it can run here.

Anything that goes wrong in here (a bad `[speech.options]` setting, the
package missing) is raised to the service, which keeps serving the socket
API and reports the reason in `health`. A missing microphone or Vosk model
is not an error here: the speech input keeps retrying and reports it in its
own health.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def start_speech(
    options: dict[str, Any],
    profile_path: str,
    on_transcript: Callable[[Any], None],
    on_event: Callable[[Any], None],
) -> Any:
    from agent.speech import SpeechConfig, SpeechInput

    # Recognition is biased toward the words of the same robot profile the daemon uses.
    config = SpeechConfig.from_dict({"profile": profile_path or None, **options})
    speech = SpeechInput(config, on_transcript=on_transcript, on_event=on_event)
    speech.start()
    return speech
