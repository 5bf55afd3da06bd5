"""Putting a part of the robot back as it was, as the profile's `[[back]]` tables say.

"Look left 30 degrees, then look straight ahead again" asks the head to pan
back by what it panned. The model reads such an ending as a drive ("straight
ahead") or as more of the same turn; the amount to undo is already in the
plan, so the steps are worked out from the skills' opposites instead.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass

from agent.translate.vocabulary import skill_parts
from rsl.plan import Plan, Quantity, format_number
from rsl.profile import Profile

# Where the clause that puts the part back begins: after the last of these before its phrase.
_CLAUSE_BREAK = re.compile(r",|;|\band then\b|\bthen\b|\bafter that\b|\bafterwards\b|\band\b")
# Words that may follow the phrase and ask for nothing more.
_TRAILING = re.compile(r"[\s,]*(?:(?:again|please|now|too|as well)[\s,]*)*$")
# An amount left after undoing that is below the precision RSL writes (see format_number).
_NOTHING_LEFT = 0.00005


@dataclass(frozen=True)
class PutBack:
    """A task that ends by putting a part back: the text before that clause, and the part."""

    before: str
    part: str
    phrase: str


def put_back(task: str, profile: Profile) -> PutBack | None:
    """The part a normalized task's last clause puts back, with the text before it; None when it puts
    none back or says nothing before it (then there is nothing to undo, and the task is read whole)."""
    for back in profile.back:
        for found in _said(back.phrases).finditer(task):
            if not _TRAILING.fullmatch(task, found.end()):
                continue
            breaks = list(_CLAUSE_BREAK.finditer(task, 0, found.start()))
            before = task[:breaks[-1].start()].strip(" ,") if breaks else ""
            if before:
                return PutBack(before=before, part=back.part, phrase=found.group(0))
    return None


@functools.cache
def _said(phrases: tuple[str, ...]) -> re.Pattern[str]:
    """Where any of a `[[back]]` table's phrases is said."""
    # Longest first, so "look straight ahead again" is read whole where "look straight ahead" would do.
    alternatives = "|".join(re.escape(p) for p in sorted(phrases, key=len, reverse=True))
    return re.compile(rf"\b(?:{alternatives})\b")


def undoing(plan: Plan, part: str, profile: Profile) -> str:
    """RSL for the steps that undo `part`'s movement in `plan`: for each pair of opposite skills on the
    part, the net amount the other way; the pair moved last is undone first. Empty when it ends as it began."""
    parts = skill_parts(profile)
    net: dict[tuple[str, str], float] = {}  # (a skill, its opposite) -> the amount moved the first one's way
    for command in plan:
        skill = profile.skill(command.skill)
        if (skill is None or skill.opposite is None or parts.get(skill.keyword) != part
                or len(command.args) != 1 or not isinstance(command.args[0], Quantity)):
            continue
        first, second = sorted((skill.keyword, skill.opposite))
        way = 1.0 if skill.keyword == first else -1.0
        # Taken out and put back, so the pair moved last comes last.
        net[(first, second)] = net.pop((first, second), 0.0) + way * command.number()
    statements = []
    for (first, second), amount in reversed(net.items()):
        if abs(amount) >= _NOTHING_LEFT:
            statements.append(f"{second if amount > 0 else first} {format_number(abs(amount))};\n")
    return "".join(statements)
