"""Connects the speech input (agent.speech) to the service, if it can run here.

Anything that goes wrong in here (no audio device, no Vosk model, the
package missing) is raised to the service, which keeps serving the socket
API and reports the reason in `health`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def start_speech(options: dict[str, Any], on_transcript: Callable[[Any], None], on_event: Callable[[Any], None]) -> Any:
    from agent.speech import SpeechConfig, SpeechInput

    from_dict = getattr(SpeechConfig, "from_dict", None)
    config = from_dict(options) if from_dict is not None else SpeechConfig(**options)
    speech = SpeechInput(config, on_transcript=on_transcript, on_event=on_event)
    speech.start()
    return speech
