"""Splitting a normalized task into clauses a tiny model can translate one at a time.

Splitting is driven by the profile's skill words (keywords and aliases), so
"grasp the cup and the ball" stays one clause while "grasp the cup and turn
left" becomes two. Pronouns are resolved to the last named object, and
"N times" becomes a repetition of the clause (or of everything before it).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from agent.translate.names import NOT_NAMES
from rsl.plan import format_number
from rsl.profile import Profile

_JOINERS = re.compile(r"\s*(?:,\s*and then|,\s*then|,\s*after that|,\s*afterwards|,\s*next|\band then\b|"
                      r"\bthen\b|\bafter that\b|\bafterwards\b|\bfinally\b|;)\s*")
_TIMES = re.compile(r"^(?P<body>.*?)\s*\b(?P<count>\d+) times$")
_REPEAT_ALL = re.compile(r"^(?:repeat|do)(?: (?:that|this|it|all|everything|the whole thing))?"
                         r"(?: again)?(?: (?P<count>\d+) times)?$")
_OBJECT = re.compile(r"\bthe ((?:[a-z]+ )?[a-z]+)\b")
_PRONOUN = re.compile(r"\b(it|them|that one)\b")
# What "it" may stand for: never a word that names no thing, nor the floor things lie on, which names
# one only in a pair ("the floor lamp").
_NOT_OBJECTS = NOT_NAMES | {"floor"}


@dataclass(frozen=True)
class Clause:
    text: str
    repeat: int = 1
    # Repeat what was translated before this clause, `repeat` times in all:
    # the last `span` clauses, or everything when `span` is 0.
    repeat_previous: bool = False
    span: int = 0


# A regular polygon is its sides repeated: drive a side, turn 2*pi/N.
SHAPES = {"triangle": 3, "square": 4, "pentagon": 5, "hexagon": 6, "octagon": 8}
_SHAPE = re.compile(r"\b(?:a |an )?(" + "|".join(SHAPES) + r")\b")
_LENGTH = re.compile(r"(\d*\.?\d+) m\b")


def split_clauses(task: str, profile: Profile) -> list[Clause]:
    """Clauses of a normalized task, in order; never empty for a non-empty task."""
    verbs = _skill_words(profile)
    pieces = [p for p in _JOINERS.split(task) if p and p.strip(" ,")]
    parts: list[str] = []
    for piece in pieces:
        parts.extend(_split_commas_and_ands(piece.strip(" ,"), verbs))
    clauses: list[Clause] = []
    last_object = ""
    for part in parts:
        named = [m for m in _OBJECT.findall(part) if m.split()[-1] not in _NOT_OBJECTS]
        if last_object and not named and _PRONOUN.search(part):
            part = _PRONOUN.sub(f"the {last_object}", part)
        if named:
            last_object = named[-1]
        shape = _SHAPE.search(part)
        if shape is not None:
            clauses.extend(_polygon(part, SHAPES[shape.group(1)]))
            continue
        repeat_all = _REPEAT_ALL.match(part)
        if repeat_all and clauses:
            count = int(repeat_all.group("count") or 2)
            clauses.append(Clause(text=part, repeat=count, repeat_previous=True))
            continue
        times = _TIMES.match(part)
        if times and times.group("body"):
            clauses.append(Clause(text=times.group("body"), repeat=max(1, int(times.group("count")))))
        else:
            clauses.append(Clause(text=part))
    return clauses or [Clause(text=task)]


def _polygon(text: str, sides: int) -> list[Clause]:
    """`drive in a square with 2 m sides` -> drive 2 m, turn 1.5708 rad, both 4 times."""
    length = _LENGTH.search(text)
    side = length.group(1) if length else "1"
    direction = "right" if re.search(r"\b(right|clockwise)\b", text) and "counter" not in text else "left"
    angle = format_number(2 * math.pi / sides)
    return [Clause(text=f"drive forward {side} m"), Clause(text=f"turn {direction} {angle} rad"),
            Clause(text=text, repeat=sides, repeat_previous=True, span=2)]


def _skill_words(profile: Profile) -> frozenset[str]:
    words = set(profile.keywords)
    for skill in profile.skills:
        words.update(skill.aliases)
    words.update({"turn", "look", "go", "drive", "move", "pick", "rotate", "spin", "face", "search", "repeat",
                  "do", "come", "return", "head", "walk", "tilt", "pan", "stop"})
    return frozenset(words)


def _split_commas_and_ands(text: str, verbs: frozenset[str]) -> list[str]:
    """Split on `,` and `and` only where a new action starts (not inside `goto 1, 2`)."""
    words = text.split(" ")
    parts: list[list[str]] = [[]]
    for index, word in enumerate(words):
        following = words[index + 1].rstrip(",") if index + 1 < len(words) else ""
        if word == "and" and following in verbs and parts[-1]:
            parts.append([])
            continue
        if word.endswith(",") and following in verbs:
            parts[-1].append(word[:-1])
            parts.append([])
            continue
        parts[-1].append(word)
    return [" ".join(p).strip(" ,") for p in parts if p and " ".join(p).strip(" ,")]
