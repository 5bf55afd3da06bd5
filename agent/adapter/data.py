"""Training pairs (task, RSL program) generated from a robot profile.

Everything robot-specific comes from the profile: which skills exist, their
keywords, aliases, units, ranges, the workspace and the conventions for vague
amounts. The phrasing below only knows kinds of skill (driving, turning,
looking, perceiving, approaching, grasping, going to a point), worked out from
each skill's parameters and description, so a robot with other skills gets
its own data without code changes; a skill of no known kind still gets plain
"keyword value unit" phrasings.

Programs are built as `Plan`s and printed canonically, and every program is
compiled against the profile before it is used.
"""

from __future__ import annotations

import hashlib
import json
import math
import random
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from agent.adapter.prompt import adapter_prompt, program_objects
from agent.corrections import CORRECTIONS
from agent.normalize import normalize_task
from rsl.plan import Command, ObjectRef, Plan, Quantity, format_number
from rsl.profile import Convention, Profile, Skill
from rsl.syntax import NO_PROGRAM

OBJECTS = (
    "cup", "mug", "bottle", "ball", "box", "book", "can", "apple", "banana", "orange", "phone",
    "remote", "bag", "shoe", "toy", "plate", "bowl", "pen", "key", "chair", "table", "door",
    "sponge", "block", "cube", "glass", "jar", "basket", "towel", "hammer", "screwdriver", "tray",
    "marker", "wallet", "lamp", "plant", "laptop", "bin", "pillow", "doll",
)


@dataclass(frozen=True)
class Pair:
    """One training example: what was said, what the model sees, what it should write."""

    task: str
    normalized: str
    program: str
    group: str
    prompt: str  # what the model is given: `adapter_prompt` of the normalized task


@dataclass(frozen=True)
class Role:
    """What a skill does, in words the phrasing templates understand."""

    kind: str  # drive, turn, look, perceive, approach, grasp, goto or other
    direction: str  # forward, back, left, right, up, down, or ""
    skill: Skill


# Phrasings by kind and direction. `{a}` is the amount ("2 meters").
PHRASES: dict[tuple[str, str], tuple[str, ...]] = {
    ("drive", "forward"): (
        "move forward {a}", "go forward {a}", "drive forward {a}", "move ahead {a}", "go straight {a}",
        "drive straight ahead {a}", "advance {a}", "roll forward {a}", "head forward {a}", "move {a} forward",
        "go {a} forward", "drive {a} ahead", "move forward by {a}", "go ahead {a}", "drive {a}",
        "move {a}", "go {a} straight ahead", "travel forward {a}", "walk forward {a}", "scoot forward {a}",
        "step forward {a}", "proceed forward {a}", "go straight on {a}", "move the base forward {a}",
        "drive ahead for {a}", "roll ahead {a}", "go on ahead {a}",
    ),
    ("drive", "back"): (
        "move backward {a}", "go back {a}", "drive backwards {a}", "back up {a}", "reverse {a}",
        "move back {a}", "retreat {a}", "drive backward by {a}", "go {a} backwards", "move {a} back",
        "back up by {a}", "reverse {a} straight back", "roll back {a}", "step back {a}", "back off {a}",
        "go in reverse {a}", "move backwards {a}", "scoot back {a}", "drive in reverse for {a}",
    ),
    ("turn", "left"): (
        "turn left {a}", "rotate left {a}", "turn {a} to the left", "rotate {a} counterclockwise",
        "spin left {a}", "turn left by {a}", "rotate to the left by {a}", "turn counterclockwise {a}",
        "make a left turn of {a}", "rotate {a} left", "turn to the left {a}", "pivot left {a}",
        "swing left {a}", "turn your body left {a}", "rotate the base left {a}", "turn yourself left {a}",
    ),
    ("turn", "right"): (
        "turn right {a}", "rotate right {a}", "turn {a} to the right", "rotate {a} clockwise",
        "spin right {a}", "turn right by {a}", "rotate to the right by {a}", "turn clockwise {a}",
        "make a right turn of {a}", "rotate {a} right", "turn to the right {a}", "pivot right {a}",
        "swing right {a}", "turn your body right {a}", "rotate the base right {a}", "turn yourself right {a}",
    ),
    ("look", "up"): (
        "look up {a}", "tilt the head up {a}", "tilt the camera up {a}", "raise your head {a}",
        "look upward {a}", "tilt up {a}", "look up by {a}", "aim the camera up {a}", "tilt your head up {a}",
        "point the camera up {a}", "glance up {a}", "move your head up {a}", "raise the camera {a}",
    ),
    ("look", "down"): (
        "look down {a}", "tilt the head down {a}", "tilt the camera down {a}", "lower your head {a}",
        "look downward {a}", "tilt down {a}", "look down by {a}", "aim the camera down {a}",
        "tilt your head down {a}", "point the camera down {a}", "glance down {a}", "lower the camera {a}",
    ),
    ("look", "left"): (
        "look left {a}", "look to the left {a}", "pan the head left {a}", "turn your head left {a}",
        "pan the camera to the left {a}", "pan left {a}", "look {a} to the left", "glance left {a}",
        "turn your head to the left {a}", "move the camera left {a}", "look over to the left {a}",
        "swivel the camera left {a}", "point the camera left {a}",
    ),
    ("look", "right"): (
        "look right {a}", "look to the right {a}", "pan the head right {a}", "turn your head right {a}",
        "pan the camera to the right {a}", "pan right {a}", "look {a} to the right", "glance right {a}",
        "turn your head to the right {a}", "move the camera right {a}", "look over to the right {a}",
        "swivel the camera right {a}", "point the camera right {a}",
    ),
}

# Verb phrases for the same motions without an amount (the profile's default applies).
BARE: dict[tuple[str, str], tuple[str, ...]] = {
    ("drive", "forward"): ("move forward", "go forward", "drive forward", "go straight", "move ahead",
                           "drive ahead", "advance", "go straight ahead", "scoot forward", "step forward",
                           "go straight", "roll forward", "move the base forward"),
    ("drive", "back"): ("move backward", "go back", "back up", "reverse", "drive backwards", "move back",
                        "back off", "step back", "go in reverse"),
    ("turn", "left"): ("turn left", "rotate left", "turn to the left", "make a left turn", "spin left",
                       "rotate counterclockwise", "take a left", "face left", "pivot left", "turn your body left"),
    ("turn", "right"): ("turn right", "rotate right", "turn to the right", "make a right turn",
                        "spin right", "rotate clockwise", "take a right", "face right", "pivot right",
                        "turn your body right"),
    ("look", "up"): ("look up", "tilt the head up", "look upward", "tilt the camera up", "raise your head",
                     "glance up", "tilt your head up", "point the camera up", "look at the ceiling"),
    ("look", "down"): ("look down", "tilt the head down", "look downward", "tilt the camera down",
                       "lower your head", "look at the floor", "glance down", "tilt your head down",
                       "point the camera down"),
    ("look", "left"): ("look left", "look to the left", "pan the head left", "turn your head left",
                       "pan the camera left", "glance left", "turn your head to the left", "glance to your left",
                       "look to your left", "look over your left shoulder"),
    ("look", "right"): ("look right", "look to the right", "pan the head right", "turn your head right",
                        "pan the camera right", "glance right", "turn your head to the right",
                        "glance to your right", "look to your right", "look over your right shoulder"),
}

# How amounts attach to a vague phrase such as "a little" ("{v}" is the phrase).
VAGUE: dict[tuple[str, str], tuple[str, ...]] = {
    ("drive", "forward"): ("move forward {v}", "go forward {v}", "drive forward {v}", "go {v} forward",
                           "move ahead {v}", "drive {v}", "go {v}", "move {v}", "advance {v}"),
    ("drive", "back"): ("move back {v}", "go back {v}", "back up {v}", "reverse {v}", "drive backwards {v}",
                        "move backward {v}"),
    ("turn", "left"): ("turn left {v}", "rotate left {v}", "turn {v} to the left", "spin left {v}"),
    ("turn", "right"): ("turn right {v}", "rotate right {v}", "turn {v} to the right", "spin right {v}"),
    ("look", "up"): ("look up {v}", "tilt the head up {v}", "tilt up {v}"),
    ("look", "down"): ("look down {v}", "tilt the head down {v}", "tilt down {v}"),
    ("look", "left"): ("look left {v}", "look {v} to the left", "pan left {v}"),
    ("look", "right"): ("look right {v}", "look {v} to the right", "pan right {v}"),
}

# Scanning or surveying a whole room is the profile's "look around", not one perceive.
PERCEIVE = ("perceive", "look for objects", "detect objects", "see what is in front of you",
            "take a look", "observe the scene", "check what is in front of you",
            "detect what is there", "take a picture", "take a photo",
            "run object detection", "check what's there", "look at what is in front of you")
SEARCH = ("find the {o}", "look for the {o}", "search for the {o}", "locate the {o}", "spot the {o}",
          "try to find the {o}", "search the area for the {o}", "scan for the {o}", "detect the {o}")
APPROACH = ("approach the {o}", "go to the {o}", "move to the {o}", "drive up to the {o}", "go over to the {o}",
            "come to the {o}", "navigate to the {o}", "get close to the {o}", "head to the {o}",
            "drive to the {o}", "move towards the {o}", "go near the {o}", "walk up to the {o}")
APPROACH_IT = ("approach it", "go to it", "move to it", "drive up to it", "go over to it", "get close to it",
               "head to it", "drive to it", "move towards it", "go near it")
GRASP = ("grasp the {o}", "pick up the {o}", "grab the {o}", "take the {o}", "pick the {o} up",
         "get the {o}", "hold the {o}", "grip the {o}", "catch the {o}", "lift the {o}", "seize the {o}")
GRASP_IT = ("grasp it", "pick it up", "grab it", "take it", "get it", "hold it", "grip it", "lift it")
GOTO = ("go to {x}, {y}", "go to position {x}, {y}", "move to the location {x}, {y}", "drive to x {x} y {y}",
        "navigate to coordinates {x}, {y}", "go to the coordinates {x} {y}", "move to x {x}, y {y}",
        "drive to position {x} {y}", "go to location {x}, {y}", "travel to {x}, {y}", "head to {x}, {y}",
        "go to the point {x}, {y}", "move to point {x} {y}", "drive to the spot {x}, {y}",
        "go to x {x} and y {y}", "navigate to the point {x} {y}", "go to coordinate {x}, {y}")
ORIGIN = ("go back to the start", "return to the origin", "return to where you started", "go home",
          "return home", "come back to the starting position", "go back to the origin", "head back to the start",
          "drive back to the starting position", "return to the start", "go back to where you began",
          "go back home", "return to your starting place", "go back to 0, 0")
JOINERS = (", ", ", then ", " then ", " and ", " and then ", ". then ", ", after that ", ". next, ",
           " and after that ", ", and then ", ". ")
FILLERS = ("uh", "um", "uhm", "er", "okay", "please", "hmm")


# Sentence frames around a task: how people address, soften and close a request.
OPENERS = ("robot, ", "hey robot, ", "okay robot, ", "robot ", "please ", "could you ", "can you please ",
           "would you ", "i'd like you to ", "i want you to ", "i need you to ", "now ", "next, ", "alright, ",
           "go ahead and ", "let's ", "maybe ", "i think you should ", "how about you ", "your task: ",
           "thanks, now ", "ok so ", "so ", "right, ", "hey, ", "buddy, ", "listen, ", "when you're ready, ")
CLOSERS = (", please", " please", ", thanks", ", thank you", " now", " for me", ", that's all",
           " and that's it", ", ok?", " when you're ready", ", robot", " right away", " if you can")
AFTER = ("after you {x}, {y}", "once you {x}, {y}", "{y} after you {x}", "{y}, but first {x}",
         "before you {y}, {x}", "{y}, but before that {x}",
         "first {x}, and when that's done {y}", "{x}, and once you're done {y}", "{x} and afterwards {y}",
         "{x}; after that {y}", "{x} before you {y}", "begin with {x}, then {y}")
NEGATED = {"drive": ("move", "drive anywhere", "move the base", "go anywhere", "drive", "move your wheels"),
           "turn": ("turn", "rotate", "turn your body", "spin", "turn the base"),
           "look": ("move your head", "look around", "move the camera", "tilt your head"),
           "other": ("move", "go anywhere", "touch anything", "grab anything")}
NEGATION_FRAMES = ("don't {n}, just {c}", "do not {n}, {c}", "{c}, but don't {n}", "{c} without moving otherwise",
                   "no need to {n}, just {c}", "{c}, don't {n}", "don't {n}. {c}", "without {ing}, {c}",
                   "{c} only, don't {n}", "i don't want you to {n}, just {c}")
OBJECT_ADVERBS = (" gently", " carefully", " slowly", " quickly", " now", " for me", " please", " right away",
                  " with care", " firmly", " softly", " if you can")
NOT_TASKS = (
    # questions
    "what time is it", "what's the weather like", "how are you", "how are you doing today", "what can you do",
    "what's your name", "are you ready", "can you hear me", "are you there", "what are you doing",
    "where are you", "how far did you go", "how much battery do you have", "what did you see",
    "where is the {o}", "is the {o} heavy", "what color is the {o}", "did you find the {o}",
    "how far away is the {o}", "do you know where the {o} is", "why did you stop", "is that the {o}",
    "how many {o}s are there", "what is in front of you", "which way is left", "how fast can you go",
    "how big is this room", "who made you", "do you like the {o}", "is it raining", "what day is it",
    "how long will that take", "did you hear that", "what's two plus two", "are you done",
    "did you grab the {o}", "where did you put the {o}", "is the {o} still there", "have you seen the {o}",
    "how heavy can you lift", "what is that", "how old are you", "are you a robot", "can robots dream",
    "what's the plan", "how did you do that", "why are you turning", "where did you go", "what's next",
    # remarks about the robot's own moves are not a request for one
    "you moved too far", "you turned the wrong way", "that was a nice turn", "you drove very well",
    "i saw you grab the {o}", "you dropped the {o}", "the {o} is broken", "i bought a new {o}",
    # chit-chat and statements
    "nice job", "good job robot", "well done", "good robot", "i'm tired", "it's cold in here",
    "the {o} is on the table", "i dropped the {o}", "that was great", "you're doing fine", "interesting",
    "i like your camera", "my name is sam", "this is my kitchen", "the {o} looks nice", "i'm back",
    "never seen a robot like you", "what a mess", "i'll be right back", "that's funny", "oh no",
    "the meeting is at three", "my phone is ringing", "it's a nice day", "i'm going to make coffee",
    # thanks, closings, greetings
    "thanks", "thank you", "thank you so much", "thanks a lot", "cheers", "much appreciated",
    "that's all", "that's all for now", "we're done here", "cheers, we're done here", "that will be all",
    "bye", "goodbye", "see you later", "good night", "talk to you later", "we're finished", "all done",
    "that's it for today", "ok that's everything", "thanks, that's all", "you can rest now",
    "hello", "hi", "hi robot", "hello robot", "good morning", "good afternoon", "hey there", "hey",
    # skills this robot does not have
    "sing a song", "tell me a joke", "make me a coffee", "call my mom", "play some music", "dance for me",
    "jump", "fly up to the ceiling", "open the door", "close the window", "wash the {o}", "cook dinner",
    "clean the floor", "turn on the lights", "turn off the tv", "order a pizza", "read me a book",
    "throw the {o}", "open the {o}", "paint the {o}", "cut the {o}", "break the {o}", "eat the {o}",
    "charge yourself", "send an email", "set an alarm", "climb the stairs", "swim", "speak louder",
    "water the plants", "fold the laundry", "kick the {o}", "sweep the floor", "write a letter",
    "translate this into french", "count to ten", "take out the trash", "make the bed", "feed the cat",
    # pure negations and calls to wait
    "don't move", "don't do anything", "do nothing", "never mind", "forget it", "cancel that",
    "don't go anywhere", "don't touch the {o}", "don't pick up the {o}", "stay where you are", "stay still",
    "hold still", "wait", "hold on a second", "don't turn", "no, don't do that", "stop", "not now",
    "don't look", "leave the {o} alone", "ignore that", "scratch that", "nothing for now", "just wait there",
)
TIMES = {2: ("2 times", "two times", "twice"), 3: ("3 times", "three times", "thrice"),
         4: ("4 times", "four times", "for times"), 5: ("5 times", "five times"), 6: ("6 times", "six times")}
POLYGONS = {3: ("triangle",), 4: ("square",), 5: ("pentagon",), 6: ("hexagon",)}

_ONES = ("zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten", "eleven",
         "twelve", "thirteen", "fourteen", "fifteen", "sixteen", "seventeen", "eighteen", "nineteen")
_TENS = ("", "", "twenty", "thirty", "forty", "fifty", "sixty", "seventy", "eighty", "ninety")


_NUMBER_WORDS = frozenset((*_ONES, *_TENS[2:], "hundred", "half", "and", "to", "too", "for"))


def number_words(value: int) -> str:
    """English words for 0..999 ("one hundred and twenty")."""
    if value < 20:
        return _ONES[value]
    if value < 100:
        tens, ones = divmod(value, 10)
        return _TENS[tens] + (f" {_ONES[ones]}" if ones else "")
    hundreds, rest = divmod(value, 100)
    return f"{_ONES[hundreds]} hundred" + (f" and {number_words(rest)}" if rest else "")


def classify(skill: Skill) -> Role:
    """The kind of motion a skill makes, read from its parameters and description."""
    text = f"{skill.keyword} {skill.description}".lower()
    params = skill.params
    direction = next((d for d in ("left", "right", "up", "down") if d in skill.keyword), "")
    if not params:
        return Role("perceive", "", skill)
    if len(params) == 2 and all(p.is_coordinate for p in params):
        return Role("goto", "", skill)
    if len(params) == 1 and params[0].kind == "object":
        if re.search(r"\b(pick|grasp|grip|grab)", text):
            return Role("grasp", "", skill)
        if re.search(r"\b(drive|approach|go|move)", text):
            return Role("approach", "", skill)
        return Role("other", "", skill)
    if len(params) == 1 and params[0].unit == "m":
        return Role("drive", "back" if "back" in text else "forward", skill)
    if len(params) == 1 and params[0].unit == "rad" and direction:
        if re.search(r"\b(head|camera|look|pan|tilt)", text):
            return Role("look", direction, skill)
        if direction in ("left", "right"):
            return Role("turn", direction, skill)
    return Role("other", "", skill)


@dataclass(frozen=True)
class Amount:
    """A vague amount from the profile: `phrase` means `value` for the given kinds."""

    phrase: str
    value: float
    unit: str
    kinds: tuple[str, ...]


_KIND_WORDS = {"driving": "drive", "turning": "turn", "looking": "look", "moving": "drive"}


def convention_amounts(conventions: Sequence[Convention]) -> tuple[list[Amount], list[Amount]]:
    """(vague amounts, default amounts) read from the profile's conventions.

    A convention whose meaning is numbers ("0.2 m when driving, 0.2618 rad when
    turning or looking") is an amount; one whose phrase is not in its own
    example task ("no amount given") gives the defaults for a bare command.
    """
    vague: list[Amount] = []
    defaults: list[Amount] = []
    for convention in conventions:
        matches = list(re.finditer(r"(\d+(?:\.\d+)?)\s*(m|rad)\b", convention.meaning))
        if not matches:
            continue
        amounts = []
        for index, match in enumerate(matches):
            end = matches[index + 1].start() if index + 1 < len(matches) else len(convention.meaning)
            context = convention.meaning[match.end():end]
            kinds = tuple(kind for word, kind in _KIND_WORDS.items() if word in context)
            if not kinds:
                kinds = ("drive",) if match.group(2) == "m" else ("turn", "look")
            amounts.append(Amount(convention.phrase, float(match.group(1)), match.group(2), kinds))
        if convention.task and convention.phrase not in convention.task:
            defaults.extend(amounts)
        elif convention.task and convention.task.strip() != convention.phrase:
            vague.extend(amounts)
    return vague, defaults


def program_conventions(conventions: Sequence[Convention], profile: Profile) -> list[Convention]:
    """Conventions that are whole commands ("turn around", "look around")."""
    return [c for c in conventions
            if c.whole_command and c.task and _parse_program(c.program, profile) is not None]


def _parse_program(text: str, profile: Profile) -> list[Command] | None:
    """The commands of a convention's program, read by the compiler; None when it does not compile."""
    from rsl.compiler import compile_program

    plan = compile_program(text, profile).plan
    return None if plan is None else list(plan)


@dataclass(frozen=True)
class Clause:
    text: str
    commands: tuple[Command, ...]
    obj: str | None = None  # the object a later "it" refers to


class Generator:
    """Seeded generator of (task, program) pairs for one profile."""

    def __init__(self, profile: Profile, seed: int = 0) -> None:
        self.profile = profile
        self.rng = random.Random(seed)
        self.roles = [classify(s) for s in profile.skills]
        self.by_motion = {(r.kind, r.direction): r for r in self.roles if r.kind in ("drive", "turn", "look")}
        self.vague, self.defaults = convention_amounts(profile.conventions)
        self.whole = program_conventions(profile.conventions, profile)
        self.first = {r.kind: r for r in reversed(self.roles)}

    # --- amounts -------------------------------------------------------
    def _pick(self, options: Sequence[str]) -> str:
        return self.rng.choice(options)

    def _say_distance(self, value: float) -> str:
        rng = self.rng
        meters = self._pick(("meters", "meters", "m", "metres", "meter"))
        if value == 1 and rng.random() < 0.4:
            return self._pick(("1 meter", "one meter", "a meter", "one metre"))
        if value == 0.5 and rng.random() < 0.5:
            return self._pick(("half a meter", "half a metre", "0.5 meters", "50 centimeters"))
        if value < 3 and round(value * 100) == value * 100 and rng.random() < 0.3:
            cm = round(value * 100)
            return f"{cm if rng.random() < 0.7 else number_words(cm)} " + self._pick(
                ("centimeters", "cm", "centimetres"))
        if value == int(value) and rng.random() < 0.35:
            return f"{number_words(int(value))} {meters}"
        if value != int(value) and value * 2 == int(value * 2) and value > 1 and rng.random() < 0.2:
            return f"{number_words(int(value))} and a half meters"
        return f"{format_number(value)} {meters}"

    def _say_angle(self, degrees: float | None, radians: float) -> str:
        rng = self.rng
        if degrees is None:
            return f"{format_number(radians)} " + self._pick(("radians", "rad", "radian"))
        deg = int(degrees)
        if deg == 90 and rng.random() < 0.15:
            return "a quarter turn"
        if deg == 180 and rng.random() < 0.15:
            return "half a turn"
        word = number_words(deg) if rng.random() < 0.3 else str(deg)
        return f"{word} " + self._pick(("degrees", "degrees", "deg", "degree"))

    def _amount(self, role: Role) -> tuple[float, str]:
        """A random amount for a drive or turn, and how a person says it."""
        if role.kind == "drive":
            value = self._distance(role)
            return value, self._say_distance(value)
        degrees, angle = self._angle(role)
        return angle, self._say_angle(degrees, angle)

    def _distance(self, role: Role) -> float:
        param = role.skill.params[0]
        low, high = param.min or 0.01, param.max or 10.0
        while True:
            r = self.rng.random()
            if r < 0.45:
                value = float(self.rng.choice((1, 1, 2, 2, 3, 3, 4, 5, 6, 7, 8, 10)))
            elif r < 0.7:
                value = self.rng.choice((0.5, 1.5, 2.5, 3.5, 0.25, 0.75, 1.25, 4.5))
            elif r < 0.85:
                value = self.rng.choice((10, 20, 25, 30, 40, 50, 60, 70, 75, 80, 90, 120, 150, 200)) / 100
            else:
                value = round(self.rng.uniform(0.1, 9.9), self.rng.choice((1, 2)))
            if low <= value <= high:
                return value

    def _angle(self, role: Role) -> tuple[float | None, float]:
        param = role.skill.params[0]
        low, high = param.min or 0.01, param.max or 6.3
        while True:
            if self.rng.random() < 0.82:
                choices = (10, 15, 20, 30, 45, 60, 90, 90, 90, 45, 30, 120, 135, 180, 180, 270, 360, 5, 25,
                           40, 50, 70, 75, 80, 100, 150, 200, 720) if role.kind == "turn" else (
                    5, 10, 15, 20, 25, 30, 30, 40, 45, 45, 60, 70, 80, 90, 120, 180)
                degrees: float | None = float(self.rng.choice(choices))
                assert degrees is not None
                radians = round(math.radians(degrees), 4)
            else:
                degrees = None
                radians = round(self.rng.uniform(0.1, min(high, 6.0)), self.rng.choice((1, 1, 2)))
            if low <= radians <= high:
                return degrees, radians

    # --- clauses -------------------------------------------------------
    def motion(self, role: Role, style: str = "any") -> Clause:
        """A drive/turn/look clause with an explicit, vague or default amount."""
        key = (role.kind, role.direction)
        unit = role.skill.params[0].unit
        param = role.skill.params[0]
        vague = [a for a in self.vague if role.kind in a.kinds and a.unit == unit
                 and (param.min or 0) <= a.value <= (param.max or math.inf)]
        default = next((a for a in self.defaults if role.kind in a.kinds and a.unit == unit), None)
        r = self.rng.random()
        if (style == "vague" and vague) or (style == "any" and vague and r < 0.12):
            amount = self.rng.choice(vague)
            return Clause(self._pick(VAGUE[key]).format(v=amount.phrase), (self._cmd(role, amount.value),))
        if default is not None and (style == "bare" or (style == "any" and r < 0.22)):
            return Clause(self._pick(BARE[key]), (self._cmd(role, default.value),))
        value, said = self._amount(role)
        templates = PHRASES[key] + tuple(f"{a} {{a}}" for a in self._alias_verbs(role))
        return Clause(self._pick(templates).format(a=said), (self._cmd(role, value),))

    def _alias_verbs(self, role: Role) -> list[str]:
        words = [a for a in role.skill.aliases if a.isalpha()]
        if role.kind == "turn":
            # A bare alias like "left" or "turn" reads as a direction-less turn.
            return [w for w in words if w not in ("turn", "rotate", "spin")]
        return words

    def _cmd(self, role: Role, *values: float | str) -> Command:
        args: list[Quantity | ObjectRef] = []
        for param, value in zip(role.skill.params, values, strict=True):
            args.append(ObjectRef(str(value)) if param.kind == "object" else Quantity(float(value), param.unit))
        return Command(role.skill.keyword, tuple(args), 0, 0)

    def object_clause(self, kind: str, obj: str, refer: bool) -> Clause | None:
        role = self.first.get(kind)
        if role is None:
            return None
        templates = {"approach": (APPROACH, APPROACH_IT), "grasp": (GRASP, GRASP_IT)}[kind]
        text = self._pick(templates[1] if refer else templates[0]).format(o=obj.replace("_", " "))
        if kind == "grasp" and self.rng.random() < 0.15:
            text += self._pick(OBJECT_ADVERBS)  # "pick up the book gently": the adverb is no part of the name
        return Clause(text, (self._cmd(role, obj),), obj)

    def perceive(self, obj: str | None = None) -> Clause | None:
        role = self.first.get("perceive")
        if role is None:
            return None
        if obj is not None:
            return Clause(self._pick(SEARCH).format(o=obj), (self._cmd(role),), obj)
        aliases = [a for a in role.skill.aliases if a.isalpha()]
        return Clause(self._pick(PERCEIVE + tuple(aliases)), (self._cmd(role),))

    def goto(self) -> Clause | None:
        role = self.first.get("goto")
        if role is None:
            return None
        coords = []
        for param in role.skill.params:
            low, high = param.min or -5.0, param.max or 5.0
            value = round(self.rng.uniform(max(low, -5.0), min(high, 5.0)) * self.rng.choice((1, 2))) / 2
            if self.rng.random() < 0.2:
                value = round(self.rng.uniform(max(low, -5.0), min(high, 5.0)), 1)
            coords.append(value)
        text = self._pick(GOTO).format(x=format_number(coords[0]), y=format_number(coords[1]))
        return Clause(text, (self._cmd(role, *coords),))

    def origin(self) -> Clause | None:
        role = self.first.get("goto")
        if role is None:
            return None
        return Clause(self._pick(ORIGIN), (self._cmd(role, 0.0, 0.0),))

    def whole_convention(self) -> Clause | None:
        if not self.whole:
            return None
        plain = [c for c in self.whole if not program_objects(c.program, self.profile)]
        if not plain:
            return None
        convention = self.rng.choice(plain)
        commands = _parse_program(convention.program, self.profile) or []
        text = self.rng.choice((convention.task, convention.phrase, convention.task))
        return Clause(text, tuple(commands))

    def other(self, role: Role) -> Clause:
        values: list[float | str] = []
        words = []
        for param in role.skill.params:
            if param.kind == "object":
                obj = self.rng.choice(OBJECTS)
                values.append(obj)
                words.append(f"the {obj}")
            else:
                low, high = param.min if param.min is not None else 0.1, param.max or 1.0
                value = round(self.rng.uniform(max(low, 0.01), high), 1)
                values.append(value)
                words.append(f"{format_number(value)} {param.unit}".strip())
        verb = self.rng.choice((role.skill.keyword, *[a for a in role.skill.aliases if a.isalpha()]))
        return Clause(" ".join([verb.replace("_", " "), *words]), (self._cmd(role, *values),))

    def simple(self) -> Clause:
        """One clause of any skill; every skill is reachable."""
        role = self.rng.choice(self.roles)
        if role.kind in ("drive", "turn", "look"):
            return self.motion(role)
        if role.kind == "perceive":
            clause = self.perceive(self.rng.choice(OBJECTS) if self.rng.random() < 0.4 else None)
        elif role.kind in ("approach", "grasp"):
            clause = self.object_clause(role.kind, self.rng.choice(OBJECTS), refer=False)
        elif role.kind == "goto":
            clause = self.goto() if self.rng.random() < 0.75 else self.origin()
        else:
            clause = self.other(role)
        return clause if clause is not None else self.other(role)

    def step(self) -> Clause:
        """One clause of a multi-step task; whole-command conventions ("look around") among them."""
        if self.whole and self.rng.random() < 0.12:
            return self.whole_convention() or self.simple()
        return self.simple()

    def fetch(self) -> list[Clause]:
        """Searching, approaching and grasping one object, with "it" references."""
        obj = self.rng.choice(OBJECTS)
        steps: list[Clause | None] = []
        shape = self.rng.random()
        if shape < 0.3:
            steps = [self.perceive(obj), self.object_clause("approach", obj, True),
                     self.object_clause("grasp", obj, True)]
        elif shape < 0.5:
            steps = [self.perceive(obj), self.object_clause("grasp", obj, True)]
        elif shape < 0.7:
            steps = [self.object_clause("approach", obj, False), self.object_clause("grasp", obj, True)]
        elif shape < 0.85:
            steps = [self.whole_convention(), self.object_clause("approach", obj, False),
                     self.object_clause("grasp", obj, True)]
        else:
            steps = [self.perceive(obj), self.object_clause("approach", obj, True),
                     self.object_clause("grasp", obj, True), self.origin()]
        return [s for s in steps if s is not None]

    def repetition(self) -> tuple[str, list[Command]] | None:
        forward = self.by_motion.get(("drive", "forward"))
        turns = [self.by_motion[k] for k in (("turn", "left"), ("turn", "right")) if k in self.by_motion]
        r = self.rng.random()
        if r < 0.35 and forward and turns:
            return self._polygon(forward, turns)
        if r < 0.55 and turns:
            return self._full_circle(turns)
        if not self.by_motion:
            return None
        body = [self.motion(self._motion_role()) for _ in range(self.rng.choice((1, 2, 2)))]
        if self.rng.random() < 0.2 and self.first.get("perceive"):
            body.append(self.perceive() or body[0])
        count = self.rng.choice((2, 2, 3, 3, 4, 4, 5, 6))
        body_text = self._join([c.text for c in body])
        times = self._pick(TIMES[count])
        text = self._pick((f"{body_text} {times}", f"repeat {times}: {body_text}", f"{body_text}, repeat {times}",
                           f"{body_text}, and do that {times}", f"do this {times}: {body_text}",
                           f"{body_text}, repeat that {times}"))
        return text, [c for _ in range(count) for clause in body for c in clause.commands]

    def _scoped_repetition(self) -> tuple[str, list[Command]] | None:
        """Repetition forms whose scope people mark in many ways ("repeat X and Y 3 times")."""
        if not self.by_motion:
            return None
        count = self.rng.choice((2, 2, 3, 3, 4, 5))
        times = self._pick(TIMES[count])
        r = self.rng.random()
        if r < 0.35:
            # "turn left 3 times 90 degrees": the count inside one clause.
            role = self._motion_role()
            key = (role.kind, role.direction)
            value, said = self._amount(role)
            template = self._pick([t for t in PHRASES[key] if t.endswith("{a}")])
            text = self._pick((template.format(a=f"{times} {said}"), f"{times} {template.format(a=said)}",
                               f"{template.format(a=said)}, {times} in a row"))
            return text, [self._cmd(role, value)] * count
        body = [self.motion(self._motion_role()) for _ in range(self.rng.choice((2, 2, 3)))]
        body_text = self._join([c.text for c in body])
        commands = [c for clause in body for c in clause.commands]
        if r < 0.7:
            text = self._pick((f"repeat {body_text} {times}", f"{times}: {body_text}",
                               f"{times} in a row, {body_text}", f"{body_text}, all of that {times}",
                               f"{body_text}, and repeat the whole thing {times}",
                               f"{body_text}, {times} over", f"do {body_text}, {times}"))
            return text, commands * count
        # A step before the repeated part is not repeated.
        before = self.simple()
        text = self._pick((f"{before.text}, then repeat {body_text} {times}",
                           f"{before.text}, then {times}: {body_text}",
                           f"{before.text}, after that do {body_text} {times}"))
        return text, list(before.commands) + commands * count

    def correction(self) -> Clause:
        """A self-correction: only what the speaker settles on counts ("1 meter, no, 2")."""
        role = self._motion_role()
        key = (role.kind, role.direction)
        if role.kind in ("turn", "look") and self.rng.random() < 0.35:
            other = {"left": "right", "right": "left", "up": "down", "down": "up"}[role.direction]
            right = self.by_motion.get((role.kind, other))
            if right is not None:
                first = self._pick(BARE[key])
                default = next((a for a in self.defaults if role.kind in a.kinds), None)
                if default is not None and self.rng.random() < 0.5:
                    # "turn left, sorry, right": the direction alone is corrected.
                    text = first + self._pick(CORRECTIONS).format(b=other)
                    return Clause(text, (self._cmd(right, default.value),))
                fixed = self.motion(right, "any")
                return Clause(first + self._pick(CORRECTIONS).format(b=fixed.text), fixed.commands)
        if role.kind == "drive":
            wrong, value = self._distance(role), self._distance(role)
            said_wrong, said = self._say_distance(wrong), self._say_distance(value)
        else:
            wrong_deg, wrong = self._angle(role)
            degrees, value = self._angle(role)
            said_wrong, said = self._say_angle(wrong_deg, wrong), self._say_angle(degrees, value)
        if wrong == value:
            return Clause(self._pick(PHRASES[key]).format(a=said), (self._cmd(role, value),))
        template = self._pick([t for t in PHRASES[key] if t.endswith("{a}")])
        text = template.format(a=said_wrong) + self._pick(CORRECTIONS).format(b=said)
        return Clause(text, (self._cmd(role, value),))

    def object_correction(self) -> Clause | None:
        kind = self.rng.choice(("approach", "grasp"))
        wrong, obj = self.rng.sample(OBJECTS, 2)
        clause = self.object_clause(kind, wrong, refer=False)
        if clause is None:
            return None
        text = clause.text + self._pick(CORRECTIONS).format(b=f"the {obj}")
        return Clause(text, (self._cmd(self.first[kind], obj),), obj)

    def negated(self) -> Clause:
        """"don't move, just look left": the negated part adds nothing."""
        clause = self.simple()
        kinds = {classify(skill).kind for c in clause.commands if (skill := self.profile.skill(c.skill))}
        if kinds & {"approach", "goto"}:
            options = ["look"]  # going somewhere drives and turns the base
        elif kinds & {"look", "perceive", "grasp"}:
            options = ["drive", "turn"]
        else:
            options = [k for k in ("turn", "look") if k not in kinds]
        negated = self._pick(NEGATED[self.rng.choice(options)])
        ing = negated.split()[0]
        ing = (ing[:-1] if ing.endswith("e") and not ing.endswith("ee") else ing) + "ing"
        ing = " ".join([ing, *negated.split()[1:]]).replace("spining", "spinning").replace("grabing", "grabbing")
        frame = self._pick(NEGATION_FRAMES)
        return Clause(frame.format(n=negated, c=clause.text, ing=ing), clause.commands)

    def ordered(self) -> tuple[str, list[Command]]:
        """Two steps said out of order: "before you X, Y", "Y after you X"."""
        first, second = self.step(), self.step()
        template = self._pick(AFTER)
        return template.format(x=first.text, y=second.text), [*first.commands, *second.commands]

    def activity(self) -> Clause | None:
        """A whole-command convention about an object ("go get the mug"), with the object varied."""
        named = [c for c in self.whole if program_objects(c.program, self.profile)]
        if not named:
            return None
        convention = self.rng.choice(named)
        old = program_objects(convention.program, self.profile)[0]
        obj = self.rng.choice(OBJECTS)
        text = re.sub(rf"\b{re.escape(old)}\b", obj, convention.task)
        if self.rng.random() < 0.3:
            text += self._pick(OBJECT_ADVERBS)
        program = re.sub(rf"\b{re.escape(old)}\b", obj, convention.program)
        return Clause(text, tuple(_parse_program(program, self.profile) or ()), obj)

    def not_a_task(self) -> str:
        text = self._pick(NOT_TASKS).format(o=self.rng.choice(OBJECTS))
        r = self.rng.random()
        if r < 0.25:
            text = self._pick(("robot, ", "hey robot, ", "hey, ", "okay, ", "so ", "um ", "well, ")) + text
        elif r < 0.4:
            text = text + self._pick(("?", ", robot", " please", "!", "?", ", thanks"))
        elif r < 0.5:
            text = self._pick(NOT_TASKS).format(o=self.rng.choice(OBJECTS)) + ", " + text
        return text

    def _frame(self, text: str) -> str:
        """A vocative, polite or hedged frame around a task, sometimes."""
        r = self.rng.random()
        if r < 0.3:
            text = self._pick(OPENERS) + text
        elif r < 0.42:
            text = text + self._pick(CLOSERS)
        elif r < 0.48:
            text = self._pick(OPENERS) + text + self._pick(CLOSERS)
        return text

    def _motion_role(self) -> Role:
        return self.rng.choice(list(self.by_motion.values()))

    def _polygon(self, forward: Role, turns: list[Role]) -> tuple[str, list[Command]]:
        sides = self.rng.choice((3, 4, 4, 4, 3, 5, 6))
        shape = self._pick(POLYGONS[sides])
        turn = turns[0] if self.rng.random() < 0.7 else turns[-1]
        side = self.rng.choice((0.5, 1.0, 1.0, 1.5, 2.0, 2.0, 3.0, 1.0))
        angle = round(2 * math.pi / sides, 4)
        said = self._say_distance(side)
        text = self._pick((f"drive in a {shape} with {said} sides", f"make a {shape} of {said}",
                           f"drive a {shape}, {said} per side", f"trace a {shape} with sides of {said}",
                           f"move in a {shape} of side {said}", f"drive a {said} {shape}",
                           f"go around a {shape} with {said} sides"))
        if turn is not turns[0] or self.rng.random() < 0.2:
            text += f", turning {turn.direction}"
        if self.rng.random() < 0.15:
            default = next((a for a in self.defaults if "drive" in a.kinds), None)
            if default is not None:
                side = default.value
                text = self._pick((f"drive in a {shape}", f"make a {shape}", f"drive a {shape}"))
                if turn is not turns[0]:
                    text += f" turning {turn.direction}"
        commands = [self._cmd(forward, side), self._cmd(turn, angle)] * sides
        return text, commands

    def _full_circle(self, turns: list[Role]) -> tuple[str, list[Command]]:
        turn = self.rng.choice(turns)
        step = self.rng.choice((30, 45, 60, 90, 90, 120, 180))
        count = 360 // step
        with_look = self.rng.random() < 0.4 and self.first.get("perceive") is not None
        said = self._say_angle(float(step), round(math.radians(step), 4))
        verb = self._pick(("turn", "rotate"))
        body = f"{verb} {turn.direction} {said}"
        if with_look:
            body += self._pick((" and perceive", " and scan", ", look for objects", " and detect objects"))
        text = self._pick((f"{body} until you complete a full circle", f"{body} at a time until a full circle",
                           f"keep going: {body} until you have turned a full circle",
                           f"{body}, repeat until a full circle"))
        step_commands = [self._cmd(turn, round(math.radians(step), 4))]
        if with_look:
            step_commands.append(self._cmd(self.first["perceive"]))
        return text, step_commands * count

    def _join(self, texts: list[str]) -> str:
        if len(texts) == 1:
            return texts[0]
        if len(texts) >= 3 and self.rng.random() < 0.25:
            return ", ".join(texts[:-1]) + self._pick((", and finally ", ", and then ", " and ")) + texts[-1]
        if self.rng.random() < 0.15:
            texts = [f"first {texts[0]}", *texts[1:]]
        out = texts[0]
        for text in texts[1:]:
            out += self._pick(JOINERS) + text
        return out

    # --- tasks ---------------------------------------------------------
    def task(self) -> tuple[str, list[Command], str]:
        """One raw task, its commands and its group ("refuse" when it has no program)."""
        r = self.rng.random()
        if r < 0.15:
            return self._surface(self.not_a_task()), [], "refuse"
        if r < 0.3:
            text, commands, group = self._base_task()
            return self._surface(self._frame(text)), commands, group
        special = self._special_task()
        if special is not None:
            text, commands, group = special
            return self._surface(self._frame(text) if self.rng.random() < 0.5 else text), commands, group
        text, commands, group = self._base_task()
        return self._surface(self._frame(text) if self.rng.random() < 0.3 else text), commands, group

    def _special_task(self) -> tuple[str, list[Command], str] | None:
        r = self.rng.random()
        if r < 0.12:
            clause = self.correction()
            return clause.text, list(clause.commands), "correction"
        if r < 0.16:
            obj_clause = self.object_correction()
            return (obj_clause.text, list(obj_clause.commands), "correction") if obj_clause else None
        if r < 0.26:
            clause = self.negated()
            return clause.text, list(clause.commands), "negation"
        if r < 0.38:
            text, commands = self.ordered()
            return text, commands, "multi-step"
        if r < 0.5:
            activity = self.activity()
            if activity is None:
                return None
            if self.rng.random() < 0.3:
                other = self.step()
                text, commands = self._join([other.text, activity.text]), [*other.commands, *activity.commands]
                return text, commands, "activity"
            return activity.text, list(activity.commands), "activity"
        if r < 0.62:
            scoped = self._scoped_repetition()
            return (scoped[0], scoped[1], "repetition") if scoped else None
        return None

    def _base_task(self) -> tuple[str, list[Command], str]:
        """The plain task shapes: one step, vague amounts, conventions, sequences, fetching, repetition."""
        r = self.rng.random()
        if r < 0.28:
            clause = self.simple()
            group = "simple"
            text, commands = clause.text, list(clause.commands)
        elif r < 0.43 and self.by_motion:
            role = self._motion_role()
            clause = self.motion(role, "vague" if self.rng.random() < 0.6 else "bare")
            text, commands, group = clause.text, list(clause.commands), "ambiguous"
        elif r < 0.5 and self.whole:
            clause = self.whole_convention() or self.simple()
            text, commands, group = clause.text, list(clause.commands), "ambiguous"
        elif r < 0.72:
            clauses = [self.step() for _ in range(self.rng.choice((2, 2, 2, 3, 3, 4, 4, 5)))]
            text = self._join([c.text for c in clauses])
            commands = [c for clause in clauses for c in clause.commands]
            group = "multi-step"
        elif r < 0.82:
            clauses = self.fetch() or [self.simple(), self.simple()]
            if self.rng.random() < 0.3:
                clauses.insert(0, self.simple())
            text = self._join([c.text for c in clauses])
            commands = [c for clause in clauses for c in clause.commands]
            group = "complex"
        else:
            repeated = self.repetition()
            if repeated is None:
                clause = self.simple()
                return clause.text, list(clause.commands), "simple"
            text, commands = repeated
            if self.rng.random() < 0.25:
                extra = self.origin() if self.rng.random() < 0.5 else self.simple()
                if extra is not None:
                    text = self._join([text, extra.text])
                    commands = commands + list(extra.commands)
            group = "complex"
        return text, commands, group

    def _surface(self, text: str) -> str:
        """Written or spoken surface form: capitals and a full stop, or ASR noise."""
        r = self.rng.random()
        if r < 0.3:
            return text[0].upper() + text[1:] + self._pick((".", "", "!"))
        if r < 0.55:
            return asr_noise(text, self.rng)
        return text

    def pairs(self, count: int, exclude: Callable[[str], bool] | None = None) -> list[Pair]:
        """`count` distinct pairs (by normalized task), skipping those `exclude` rejects."""
        out: list[Pair] = []
        seen: set[str] = set()
        attempts = 0
        while len(out) < count:
            attempts += 1
            if attempts > count * 50:
                raise RuntimeError(f"the generator could only make {len(out)} distinct pairs of {count} "
                                   f"asked for; ask for fewer")
            text, commands, group = self.task()
            if (not commands and group != "refuse") or len(commands) > self.profile.max_statements:
                continue
            normalized = normalize_task(text)
            if normalized in seen or (exclude is not None and exclude(normalized)):
                continue
            seen.add(normalized)
            program = Plan(tuple(commands), self.profile.name).to_rsl() if commands else NO_PROGRAM + "\n"
            out.append(Pair(task=text, normalized=normalized, program=program, group=group,
                            prompt=adapter_prompt(normalized, self.profile)))
        return out


# Words a speech recognizer writes for another word that sounds the same.
_MISHEARD = {"right": ("write", "rite"), "forward": ("foreword", "forwards"), "meters": ("meter", "metres"),
             "degrees": ("degree",), "grab": ("crab",), "turn": ("term",), "cup": ("cop",),
             "look": ("luck",), "left": ("lift",), "the": ("a", "da"), "then": ("than", "and")}


def asr_noise(text: str, rng: random.Random) -> str:
    """What a speech recognizer makes of a task: no case or punctuation, homophones, fillers."""
    words = re.sub(r"[^\w\s.'-]|(?<!\d)\.|\.(?!\d)", " ", text.lower()).split()
    out: list[str] = []
    for index, word in enumerate(words):
        nxt = words[index + 1] if index + 1 < len(words) else ""
        unitish = re.match(r"(meter|metre|m$|times|degree|deg|centi|cm)", nxt)
        if word in ("two", "2") and unitish and rng.random() < 0.5:
            word = rng.choice(("to", "too"))
        elif word in ("four", "4") and unitish and rng.random() < 0.5:
            word = "for"
        elif word in _MISHEARD and rng.random() < 0.15:
            word = rng.choice(_MISHEARD[word])
        # A speaker hesitates between words, not inside "2 meters".
        previous = out[-1] if out else ""
        if rng.random() < 0.06 and not (re.match(r"[\d.]+$", previous) or previous in _NUMBER_WORDS):
            out.append(rng.choice(FILLERS))
        out.append(word)
    if rng.random() < 0.3:
        out.insert(0, rng.choice(FILLERS))
    return " ".join(out)


def check_programs(pairs: Iterable[Pair], profile: Profile) -> None:
    """Compile every program against the profile; raise on the first that fails."""
    from rsl.compiler import compile_program

    for pair in pairs:
        if pair.program.strip() == NO_PROGRAM:
            continue
        result = compile_program(pair.program, profile)
        if not result.ok:
            details = "; ".join(d.brief() for d in result.diagnostics)
            raise ValueError(f"generated program for task {pair.task!r} does not compile: {details}\n"
                             f"{pair.program}")


def pair_record(pair: Pair) -> dict[str, str]:
    """One pair as `train-adapter --dump-data` writes it, a JSON line each."""
    return {"task": pair.task, "normalized": pair.normalized, "prompt": pair.prompt, "program": pair.program,
            "group": pair.group}


def data_digest(pairs: Iterable[Pair]) -> str:
    """The sha256 of `pairs` as dumped: an adapter card keeps it, so a change to the profile, the phrasing
    templates or the normalizer that would have trained the adapter on other data is found."""
    digest = hashlib.sha256()
    for pair in pairs:
        digest.update((json.dumps(pair_record(pair)) + "\n").encode("utf-8"))
    return digest.hexdigest()


def generate(profile: Profile, count: int, seed: int = 0,
             exclude: Callable[[str], bool] | None = None) -> list[Pair]:
    """`count` verified training pairs for `profile`, reproducible from `seed`."""
    pairs = Generator(profile, seed).pairs(count, exclude)
    check_programs(pairs, profile)
    return pairs
