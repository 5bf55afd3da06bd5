"""Checks of a verified plan against what the robot knows of the world, before anything moves.

- An object the plan names must be one the robot knows or can look for (a
  scene object the simulator will look for first, as it does today); any
  other name is refused before motion, as `run-program` refuses it (E104).
- A skill whose object is out of the arm's reach gets the skill the profile
  names for it (`out_of_reach = "approach"` on `grasp`) run first.
- A straight drive through an object the robot has seen is refused with where it would hit.

The base is followed from its current pose only through statements bound to
the `drive` and `turn` primitives (their sign says which way) or that do not move the base;
after any other base motion (a `goto`, an `approach`) positions are no longer
known and the checks leave the rest to the robot, which checks again as it goes.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from agent.translate.vocabulary import WHOLE, skill_parts
from rsl.compiler import compile_program
from rsl.plan import Command, ObjectRef, Plan, Quantity
from rsl.profile import Profile

# The footprint radius of an object whose size the robot does not know (one it has only seen).
_UNKNOWN_RADIUS = 0.1


@dataclass(frozen=True)
class Thing:
    name: str
    x: float
    y: float
    half_x: float  # half its extent along the world's x and y axes
    half_y: float


@dataclass(frozen=True)
class WorldCheck:
    plan: Plan | None  # the plan to run, with approaches added; None when refused
    refusal: str = ""
    added: tuple[str, ...] = ()  # statements added, e.g. "approach cup;"


def known_things(robot: Any) -> tuple[list[Thing], list[Thing], bool]:
    """What the robot can name, what it has seen, and whether the names are the whole world (a scene).

    Only a simulator's scene is the whole world: a real robot may find more by looking, so unknown names
    are left to it. Only what the robot has seen is an obstacle: it cannot plan around what it never saw.
    """
    named: dict[str, Thing] = {}
    scene = getattr(getattr(robot, "world", None), "scene", None)
    objects = getattr(scene, "objects", None)
    for obj in objects or ():
        half_x, half_y = obj.size[0] / 2, obj.size[1] / 2
        if obj.yaw:
            half_x = half_y = math.hypot(half_x, half_y)
        named[obj.name] = Thing(obj.name, obj.x, obj.y, half_x, half_y)
    try:
        state = robot.state()
    except Exception:
        return list(named.values()), [], objects is not None
    seen = []
    for name, x, y in state.known_objects:
        size = named.get(name)
        named[name] = Thing(name, x, y, size.half_x if size else _UNKNOWN_RADIUS,
                            size.half_y if size else _UNKNOWN_RADIUS)
        seen.append(named[name])
    return list(named.values()), seen, objects is not None


def check_world(plan: Plan, profile: Profile, robot: Any) -> WorldCheck:
    things, seen, whole_world = known_things(robot)
    if not things:
        return WorldCheck(plan)
    by_name = {t.name: t for t in things}
    named = sorted({a.name for c in plan for a in c.args if isinstance(a, ObjectRef)})
    unknown = [n for n in named if n not in by_name]
    if unknown and whole_world:
        return WorldCheck(None, f"the robot knows no {', '.join(unknown)} (it knows "
                                f"{', '.join(sorted(by_name))}); nothing moved. Name one of those objects.")
    try:
        state = robot.state()
        x, y, heading = state.pose.x, state.pose.y, state.pose.heading
        holding = state.holding
    except Exception:
        return WorldCheck(plan)
    parts = skill_parts(profile)
    commands: list[Command] = []
    added: list[str] = []
    tracking = True
    for command in plan:
        skill = profile.skill(command.skill)
        if skill is None:
            return WorldCheck(plan)
        if tracking and skill.out_of_reach and command.args and isinstance(command.args[0], ObjectRef):
            target = by_name.get(command.args[0].name)
            if target is not None and math.hypot(target.x - x, target.y - y) > profile.motion.reach:
                first = command.reached_by(skill.out_of_reach)
                commands.append(first)
                added.append(first.to_rsl())
                tracking = False
        primitive = skill.primitive
        moves = primitive.name if primitive is not None and command.args and isinstance(command.args[0], Quantity) \
            else ""
        if tracking and moves == "drive":
            assert primitive is not None and isinstance(command.args[0], Quantity)
            bearing = heading + (0.0 if primitive.sign > 0 else math.pi)
            distance = command.args[0].value
            hit = _first_hit(x, y, bearing, distance, profile.motion.width / 2,
                             (t for t in seen if t.name != holding))
            if hit is not None:
                thing, at = hit
                approach = profile.bound_to("approach_object")
                stop_there = (f", or `{approach.keyword} {thing.name};` to stop in front of it"
                              if approach is not None else "")
                return WorldCheck(None, f"`{command.to_rsl()}` (line {command.line}) would drive into the "
                                        f"{thing.name} after about {at:.1f} m; nothing moved. Drive less than "
                                        f"{max(0.0, at):.1f} m{stop_there}.")
            x, y = x + distance * math.cos(bearing), y + distance * math.sin(bearing)
        elif tracking and moves == "turn":
            assert primitive is not None and isinstance(command.args[0], Quantity)
            heading += primitive.sign * command.args[0].value
        elif parts.get(command.skill) == WHOLE:
            tracking = False
        commands.append(command)
    if not added:
        return WorldCheck(plan)
    # The new program is compiled like any other: only a verified plan reaches the robot.
    program = "".join(c.to_rsl() + "\n" for c in commands)
    compiled = compile_program(program, profile, list(by_name) if whole_world else None)
    if compiled.plan is None:
        return WorldCheck(plan)
    return WorldCheck(compiled.plan, added=tuple(added))


def _first_hit(x: float, y: float, bearing: float, distance: float, half_width: float,
               things: Iterable[Thing]) -> tuple[Thing, float] | None:
    """The first thing a straight drive's corridor meets, and how far along the drive the base would touch it."""
    dx, dy = math.cos(bearing), math.sin(bearing)
    first: tuple[Thing, float] | None = None
    for thing in things:
        along = (thing.x - x) * dx + (thing.y - y) * dy
        across = abs(-(thing.x - x) * dy + (thing.y - y) * dx)
        # The thing's half extents along the drive and across it.
        deep = abs(thing.half_x * dx) + abs(thing.half_y * dy)
        wide = abs(thing.half_x * dy) + abs(thing.half_y * dx)
        if across >= half_width + wide or along <= 0:
            continue
        # Where the base's front edge (taken as half a width ahead of its centre) first reaches the thing.
        touch = along - deep - half_width
        if touch < distance and (first is None or touch < first[1]):
            first = (thing, touch)
    return first
