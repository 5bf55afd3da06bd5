"""Mends: a doubted plan rewritten from what its doubts name, without generating.

A small model reads some words as words, not as edits: a take-back ("...,
actually skip the turn"), a thing said as where another is ("the keys by
the front door"), a way a convention leaves unsaid, a point said from the
start, "do that again". The check that doubts such a plan knows which steps
are wrong and what was meant, so writing the plan it meant costs no
generation. The translator tries each mend in order and takes the first
program that passes every check; it is judged on the model's own signal, as
any plan that passes them is.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from agent.translate.meaning import NOT_ASKED, Doubt, at_point, at_things, repeated, said_point
from agent.translate.vocabulary import vocabulary
from rsl.plan import Command, Plan
from rsl.profile import Profile


@dataclass(frozen=True)
class Mend:
    """One way to rewrite a doubted plan: `write` gives the program meant, or None when the doubts do not
    name what it mends. `what` says what was mended, for -v."""

    name: str
    what: str
    write: Callable[[Plan, tuple[Doubt, ...], str, Profile], str | None]


def _program(plan: Plan, commands: list[Command]) -> str:
    """The program of `commands`, in `plan`'s profile."""
    return Plan(tuple(commands), plan.profile).to_rsl()


def _left_out(plan: Plan, doubts: tuple[Doubt, ...], _task: str, _profile: Profile) -> str | None:
    """Without the steps nobody asked for: "drive forward 4 m and turn left, actually skip the turn" comes
    out with the turn, "the knife, wait, no, the ladle" with both, "the pen by your gripper, pick it up"
    picks up the gripper too."""
    dropped = {i for d in doubts if d.check in NOT_ASKED for i in d.steps}
    if not dropped:
        return None
    return _program(plan, [c for i, c in enumerate(plan) if i not in dropped])


def _reached_first(plan: Plan, doubts: tuple[Doubt, ...], _task: str, profile: Profile) -> str | None:
    """The step that reaches a thing (the profile's `out_of_reach`) put before the step the task said to go
    and do: "go pick up the mug" often comes out as `grasp mug;` alone."""
    steps = {i for d in doubts if d.check == "reach" for i in d.steps}
    if not steps:
        return None
    reached_by = vocabulary(profile).reached_by
    commands: list[Command] = []
    for i, c in enumerate(plan):
        if i in steps:
            commands.append(c.reached_by(reached_by[c.skill]))
        commands.append(c)
    return _program(plan, commands)


def _at_the_thing(plan: Plan, doubts: tuple[Doubt, ...], task: str, _profile: Profile) -> str | None:
    """Acting on the thing where the plan acted on the place said only as where it is: "head over to the
    keys by the front door" often comes out as `approach door;`, the last thing said."""
    if not any(d.check == "place" for d in doubts):
        return None
    return at_things(plan, task)


def _way_as_said(plan: Plan, doubts: tuple[Doubt, ...], _task: str, profile: Profile) -> str | None:
    """The steps that went the other way than a convention whose example says no way turned its way:
    "spin in a full circle" means what the convention's example does."""
    turned = {i for d in doubts if d.check == "unsaid way" for i in d.steps}
    if not turned:
        return None
    opposites = vocabulary(profile).opposites
    return _program(plan, [Command(opposites[c.skill], c.args, c.line, c.column) if i in turned else c
                           for i, c in enumerate(plan)])


def _point_as_said(plan: Plan, doubts: tuple[Doubt, ...], task: str, profile: Profile) -> str | None:
    """The drive to the point the task said from the start, without the steps that drove that point's
    amounts again: "the spot 2 m ahead and 1 m to your right" is exact once the profile's frame reads
    it, and the model often swaps the axes or loses a sign."""
    steps = next((d.steps for d in doubts if d.check == "point"), ())
    point = said_point(task, profile) if steps else None
    meant = at_point(plan.commands[steps[0]], point, profile) if steps and point else None
    if meant is None:
        return None
    return _program(plan, [meant if i == steps[0] else c for i, c in enumerate(plan) if i not in steps[1:]])


def _done_again(plan: Plan, doubts: tuple[Doubt, ...], task: str, profile: Profile) -> str | None:
    """The plan done again as many times as the task's end asks ("..., and repeat that once more"): what
    "that" is, everything said before, is the plan itself."""
    if not any(d.check == "again" for d in doubts):
        return None
    return repeated(plan, task, profile)


MENDS = (
    Mend("left out", "the plan did steps nobody asked for; left out", _left_out),
    Mend("at the thing", "the plan acted on a place said only as where a thing is; set to the thing", _at_the_thing),
    Mend("way as said", "the plan went the other way than the task's convention; turned", _way_as_said),
    Mend("point as said", "the plan drove elsewhere than the point said from the start; set to it", _point_as_said),
    Mend("done again", "the task asked for its steps again and the plan did them once; repeated", _done_again),
    Mend("reached first", "the task said to go to a thing and the plan acted on it where it stood; gone to first",
         _reached_first),
)
