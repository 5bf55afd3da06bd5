"""Explain-back: one plain-English sentence for a plan, worded by the robot profile.

"drive forward 3 m, then turn right 90°, then pick up the box". Each
statement is said with its skill's `say` template; a skill without one is
worded from its description. Numbers are said in the units people use:
degrees for angles, centimetres below a metre, metres above.
"""

from __future__ import annotations

import math
import re
import string

from rsl.plan import Arg, Command, ObjectRef, Plan, Quantity
from rsl.profile import Profile, Skill

_FIRST_CLAUSE = re.compile(r"[.;]")
_ARTICLE = r"\b(?:an?|the) ({names})\b"


def explain(plan: Plan, profile: Profile) -> str:
    """The whole plan as one sentence; repeated statements are said once with a count."""
    phrases: list[str] = []
    counts: list[int] = []
    for command in plan:
        phrase = say(command, profile)
        if phrases and phrases[-1] == phrase:
            counts[-1] += 1
        else:
            phrases.append(phrase)
            counts.append(1)
    parts = [p if n == 1 else f"{p} ({n} times)" for p, n in zip(phrases, counts, strict=True)]
    return ", then ".join(parts) if parts else "do nothing"


def say(command: Command, profile: Profile) -> str:
    """One statement in words: `turnright 1.5708;` -> "turn right 90°"."""
    skill = profile.skill(command.skill)
    if skill is None:
        return command.to_rsl()
    values = {p.name: spoken(a) for p, a in zip(skill.params, command.args, strict=False)}
    if skill.say:
        try:
            return string.Formatter().vformat(skill.say, (), values)
        except (KeyError, IndexError, ValueError):
            pass  # A template naming no parameter of the skill: fall back to the description.
    return _from_description(skill, values)


def spoken(arg: Arg) -> str:
    """An argument as a person says it: 1.5708 rad -> "90°", 0.3 m -> "30 cm", cup -> "the cup"."""
    if isinstance(arg, ObjectRef):
        return "the " + arg.name.replace("_", " ")
    return quantity(arg)


def quantity(value: Quantity) -> str:
    if value.unit == "rad":
        return f"{_trim(math.degrees(value.value), 0)}°"
    if value.unit == "m":
        if 0 < abs(value.value) < 1:
            return f"{_trim(value.value * 100, 0)} cm"
        return f"{_trim(value.value, 2)} m"
    return f"{_trim(value.value, 4)} {value.unit}".strip()


def _trim(number: float, places: int) -> str:
    text = f"{number:.{places}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def _from_description(skill: Skill, values: dict[str, str]) -> str:
    """The description's first clause, lower-cased, with "a distance" / "an object" replaced by the values.

    A value the wording does not name is added at the end, with its parameter's name.
    """
    text = _FIRST_CLAUSE.split(skill.description, 1)[0].strip() or skill.keyword
    text = text[0].lower() + text[1:]
    left = dict(values)
    if left:
        pattern = re.compile(_ARTICLE.format(names="|".join(map(re.escape, left))))

        def fill(match: re.Match[str]) -> str:
            return left.pop(match.group(1), match.group(0))

        text = pattern.sub(fill, text)
    if left:
        text += " (" + ", ".join(f"{name} {value}" for name, value in left.items()) + ")"
    return text


def capabilities(profile: Profile) -> str:
    """What the robot can be asked to do, one short phrase per skill, from the profile."""
    phrases = [_FIRST_CLAUSE.split(s.description, 1)[0].strip() or s.keyword for s in profile.skills]
    return "; ".join(p[0].lower() + p[1:] for p in phrases)
