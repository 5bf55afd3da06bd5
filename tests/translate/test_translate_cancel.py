"""A cancel flag ends generation mid-way, even inside one llama.cpp call, and leaves the model usable."""

from __future__ import annotations

import threading
import time

import pytest

from agent.translate import Translator
from agent.translate.engine import GenerationCancelled

LONG_TASK = " then ".join(["move forward one meter", "turn left", "look up", "turn right"] * 2)


def test_a_set_cancel_flag_ends_the_translation_and_the_next_one_is_unchanged(translator: Translator) -> None:
    before = translator.translate("turn left then look up").program
    cancel = threading.Event()
    timer = threading.Timer(0.3, cancel.set)
    timer.start()
    started = time.monotonic()
    with pytest.raises(GenerationCancelled):
        translator.translate(LONG_TASK, cancel=cancel)
    ended = time.monotonic() - started
    timer.join()
    assert translator.translate("turn left then look up").program == before, "the KV cache was left consistent"
    # Loose: the whole translation takes many times this; bench_hostile measures the 0.5 s target.
    assert ended < 3.0, f"cancelled after {ended:.2f} s"


def test_a_flag_set_before_the_call_stops_it_at_once(translator: Translator) -> None:
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(GenerationCancelled):
        translator.translate("turn left", cancel=cancel)
    assert translator.translate("turn left").verified
