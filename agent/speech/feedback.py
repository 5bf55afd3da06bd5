"""Optional spoken feedback through espeak-ng ("moving forward two meters"); off by default.

Speaking never blocks the caller and never fails it: without espeak-ng the
feedback is switched off once, with the reason logged.
"""

from __future__ import annotations

import contextlib
import logging
import math
import shutil
import subprocess
import threading

from rsl.plan import Command, ObjectRef, Quantity

log = logging.getLogger("nrtrans.speech.feedback")

_ONES = ("zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten", "eleven",
         "twelve", "thirteen", "fourteen", "fifteen", "sixteen", "seventeen", "eighteen", "nineteen")
_TENS = ("", "", "twenty", "thirty", "forty", "fifty", "sixty", "seventy", "eighty", "ninety")
# Keywords that are two words run together read better apart.
_PREFIXES = ("turn", "look", "go")


class Speaker:
    def __init__(self, voice: str = "en-us", enabled: bool = True) -> None:
        self.voice = voice
        self.enabled = enabled
        self.reason = "" if enabled else "disabled in the config"
        self._lock = threading.Lock()
        self._current: subprocess.Popen[bytes] | None = None

    def speak(self, text: str, *, wait_s: float = 0.0) -> bool:
        """Start saying `text`, cutting off anything still being said; False when feedback is off.

        `wait_s` > 0 waits up to that long for it to be said: an explanation is heard before the robot moves.
        """
        if not self.enabled:
            return False
        program = shutil.which("espeak-ng")
        if program is None:
            self.enabled = False
            self.reason = "espeak-ng is not installed (apt-get install espeak-ng)"
            log.warning("spoken feedback is off: %s", self.reason)
            return False
        with self._lock:
            if self._current is not None and self._current.poll() is None:
                self._current.terminate()
            try:
                self._current = subprocess.Popen([program, "-v", self.voice, "--", text],
                                                 stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                                 stderr=subprocess.DEVNULL)
            except OSError as exc:
                self.enabled = False
                self.reason = f"espeak-ng cannot run: {exc}"
                log.warning("spoken feedback is off: %s", self.reason)
                return False
            speaking = self._current
        if wait_s > 0:
            with contextlib.suppress(subprocess.TimeoutExpired):
                speaking.wait(wait_s)
        return True

    def close(self) -> None:
        with self._lock:
            if self._current is not None and self._current.poll() is None:
                self._current.terminate()
                self._current.wait(2)
            self._current = None


_default = Speaker()


def speak(text: str) -> bool:
    """Say `text` without waiting; False (and a logged reason, once) when espeak-ng is missing."""
    return _default.speak(text)


def describe(command: Command) -> str:
    """A short spoken phrase for one step: `turnleft 1.5708;` -> "turning left ninety degrees"."""
    words = command.skill.replace("_", " ")
    for prefix in _PREFIXES:
        if words.startswith(prefix) and len(words) > len(prefix) and words[len(prefix)] != " ":
            words = f"{prefix} {words[len(prefix):]}"
            break
    verb, _, rest = words.partition(" ")
    # A bare direction ("forward") is not a verb; "moving forward" is.
    phrase = [_gerund(verb), *rest.split()] if rest or not command.args or \
        isinstance(command.args[0], ObjectRef) else ["moving", verb]
    numbers = [_quantity(a) for a in command.args if isinstance(a, Quantity)]
    objects = [f"the {a.name.replace('_', ' ')}" for a in command.args if isinstance(a, ObjectRef)]
    return " ".join([*phrase, *objects, ", ".join(numbers)]).strip()


def _gerund(verb: str) -> str:
    if verb.endswith("e") and not verb.endswith("ee"):
        return verb[:-1] + "ing"
    return verb + "ing"


def _quantity(quantity: Quantity) -> str:
    if quantity.unit == "rad":
        degrees = round(math.degrees(quantity.value))
        return f"{number_words(degrees)} degree{'s' if degrees != 1 else ''}"
    if quantity.unit == "m":
        value = round(quantity.value, 2)
        if 0 < value < 1:
            centimetres = round(value * 100)
            return f"{number_words(centimetres)} centimeter{'s' if centimetres != 1 else ''}"
        return f"{number_words(value)} meter{'s' if value != 1 else ''}"
    return number_words(quantity.value)


def number_words(value: float) -> str:
    """English words for a number: 2 -> "two", 1.5 -> "one point five", -3 -> "minus three"."""
    if value < 0:
        return "minus " + number_words(-value)
    whole = int(value)
    fraction = f"{value:.2f}".split(".")[1].rstrip("0")
    text = _integer_words(whole)
    if fraction:
        text += " point " + " ".join(_ONES[int(d)] for d in fraction)
    return text


def _integer_words(n: int) -> str:
    if n < 20:
        return _ONES[n]
    if n < 100:
        return _TENS[n // 10] + ("" if n % 10 == 0 else " " + _ONES[n % 10])
    if n < 1000:
        rest = n % 100
        return _ONES[n // 100] + " hundred" + ("" if rest == 0 else " " + _integer_words(rest))
    return str(n)
