"""A convention's phrase said in other words, read as the phrase: "turn left slightly" is "turn left a little".

People say a vague amount in many ways, and the model learned the
profile's phrase for it; "slightly" read as it stands runs as the amount for
no amount said, a quarter turn. The profile lists the other words
(`[[conventions]] also`), so the model and the meaning checks read the
phrase. Only an amount said right after a word of a skill is read so: a
remark about an amount ("that was a long way to go") would read as an
order. It runs at run time, after the normalizer, so the adapter needs no
retraining for a word added.
"""

from __future__ import annotations

import functools
import re

from agent.translate.vocabulary import vocabulary
from rsl.profile import Convention, Profile

# A word after one of these describes a thing ("the slightly bigger box"), not how far to go.
_BEFORE_A_THING = ("the", "a", "an", "that", "this", "your", "my")


def in_convention_words(text: str, profile: Profile) -> str:
    """`text` (normalized) with each convention's other words replaced by its phrase, where they say how far
    a step goes: right after a word of a skill ("turn left slightly", "drive a long way down the hall"). A
    remark about an amount ("that was a long way to go") keeps its words, and asks for nothing."""
    pattern, phrases = _reading(profile.conventions)
    if not phrases:
        return text
    step_words = vocabulary(profile).skill_words

    def read(m: re.Match[str]) -> str:
        before = text[:m.start()].split()
        if m.group(1) or not before or before[-1] not in step_words:
            return m.group(0)
        return phrases[m.group(2)]

    return pattern.sub(read, text)


@functools.cache
def _reading(conventions: tuple[Convention, ...]) -> tuple[re.Pattern[str], dict[str, str]]:
    """A pattern of every convention's phrase and other words, the longest first so that a phrase holding
    another's word ("a bit further") is read whole, and what each stands for."""
    phrases = {word: c.phrase for c in conventions for word in c.also}
    if not phrases:
        return re.compile("(?!)"), {}
    phrases |= {c.phrase: c.phrase for c in conventions}
    alternatives = "|".join(re.escape(p) for p in sorted(phrases, key=len, reverse=True))
    return re.compile(rf"\b(?:({'|'.join(_BEFORE_A_THING)}) )?({alternatives})\b"), phrases
