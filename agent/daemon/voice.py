"""Connects the speech input (agent.speech) to the service, if it can run here.

Anything that goes wrong in here (a bad `[speech.options]` setting, the
package missing) is raised to the service, which keeps serving the socket
API and reports the reason in `health`. A missing microphone or Vosk model
is not an error here: the speech input keeps retrying and reports it in its
own health.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol

from rsl.plan import Command

if TYPE_CHECKING:
    from agent.speech import SpeechEvent, Transcript


class Speech(Protocol):
    """What the service uses of the speech input (`agent.speech.SpeechInput`)."""

    def listen_now(self) -> None:
        """Start listening for a task without the wake word; RuntimeError says why it cannot."""

    def guard(self, moving: bool) -> None:
        """While the robot moves, listen for a spoken stop without the wake word."""

    def announce(self, command: Command) -> bool:
        """Say the step about to run, when spoken feedback is on."""

    def say(self, text: str, *, wait_s: float = 0.0) -> bool: ...

    def set_objects(self, names: tuple[str, ...] | list[str]) -> None:
        """Expect these object names in what is said next."""

    def health(self) -> dict[str, Any]: ...

    def stop(self) -> None: ...


def start_speech(
    options: dict[str, Any],
    profile_path: str,
    on_transcript: Callable[[Transcript], None],
    on_event: Callable[[SpeechEvent], None],
) -> Speech:
    from agent.speech import SpeechConfig, SpeechInput

    # Recognition is biased toward the words of the same robot profile the daemon uses.
    config = SpeechConfig.from_dict({"profile": profile_path or None, **options})
    speech = SpeechInput(config, on_transcript=on_transcript, on_event=on_event)
    speech.start()
    return speech
