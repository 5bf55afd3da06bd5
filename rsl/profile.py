"""The robot profile: the one source of truth for a robot's skills.

A profile is a TOML file. Everything that knows about skills (the parser,
diagnostics, grammar export, prompt, docs, training data and the backends)
reads it from here, so adding a skill is a data change. What a skill does is
its binding: one of the robot primitives every backend implements, or a ROS 2
topic, service or joint trajectory (docs/skills.md).
"""

from __future__ import annotations

import hashlib
import json
import keyword as python_keyword
import re
import tomllib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Literal

from rsl.settings import read_settings, setting

IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
SKILL_KEYWORD = re.compile(r"[a-z][a-z0-9_]*\Z")
_AMOUNT = re.compile(r"\d\s*[a-z]+\b")
# A lower-case word, as the robot's description and a normalized task are read.
WORD = re.compile(r"[a-z]+")
# The part of the robot that moves itself as a whole: the one a skill is on when its description names no part.
WHOLE = "base"

ParamKind = Literal["number", "object"]

# The robot primitives: what the simulator and the ROS 2 backend know how to do,
# each with the parameters it takes (kind and unit) in order. A skill bound to a
# primitive must declare exactly these; its keyword is free.
PRIMITIVES: dict[str, tuple[tuple[ParamKind, str], ...]] = {
    "drive": (("number", "m"),),       # straight along the heading; sign -1 drives backward
    "turn": (("number", "rad"),),      # on the spot; sign +1 is left (counter-clockwise)
    "pan": (("number", "rad"),),       # the head; sign +1 is left
    "tilt": (("number", "rad"),),      # the head; sign +1 is up
    "navigate": (("number", "m"), ("number", "m")),  # to a point; the params' axis says which is x and y
    "approach_object": (("object", ""),),  # drive up to an object and face it
    "perceive_objects": (),                # look with the camera; objects in view become known
    "grasp_object": (("object", ""),),     # pick up an object within reach
}
SIGNED_PRIMITIVES = ("drive", "turn", "pan", "tilt")
# The ROS 2 bindings for robot-specific skills.
ROS_BINDINGS = ("topic", "trigger", "setbool", "joint_trajectory")
_ROS_NAME = re.compile(r"/?[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*\Z")
_MESSAGE_TYPE = re.compile(r"[a-z][a-z0-9_]*/msg/[A-Z][A-Za-z0-9]*\Z")
_FIELD_PATH = re.compile(r"[a-z][a-z0-9_]*(\.[a-z][a-z0-9_]*)*\Z")


class ProfileError(ValueError):
    """A robot profile that cannot be used, with the reason and where."""


@dataclass(frozen=True)
class Param:
    name: str
    kind: ParamKind
    unit: str = ""
    min: float | None = None
    max: float | None = None
    # A coordinate takes its bounds from the workspace and may be zero or
    # negative; every other number must be strictly positive.
    axis: str | None = None

    @property
    def is_coordinate(self) -> bool:
        return self.axis is not None


@dataclass(frozen=True)
class Primitive:
    """A skill that is one of the robot primitives, e.g. `drive` with sign -1 for backward."""

    name: str  # a key of PRIMITIVES
    sign: float = 1.0

    def describe(self) -> str:
        if self.name not in SIGNED_PRIMITIVES:
            return f"primitive `{self.name}`"
        return f"primitive `{self.name}`, sign {self.sign:+g}"


# A value sent to the robot: a parameter's name (its value at run time) or a constant.
Source = str | float | bool


@dataclass(frozen=True)
class RosBinding:
    """A robot-specific skill: a ROS 2 topic publish, std_srvs call or joint trajectory."""

    kind: str  # one of ROS_BINDINGS
    name: str  # the topic or service
    message_type: str = ""  # topic: e.g. std_msgs/msg/Float64
    fields: tuple[tuple[str, Source], ...] = ()  # topic: field path -> source
    data: Source = True  # setbool: the request's data
    joints: tuple[str, ...] = ()  # joint_trajectory
    positions: tuple[Source, ...] = ()  # joint_trajectory: one per joint
    duration: float = 0.0  # joint_trajectory: seconds to the point (time_from_start)

    def describe(self) -> str:
        if self.kind == "topic":
            return f"publishes {self.message_type} on {self.name}"
        if self.kind == "trigger":
            return f"calls the std_srvs/srv/Trigger service {self.name}"
        if self.kind == "setbool":
            return f"calls the std_srvs/srv/SetBool service {self.name} (data {_source_text(self.data)})"
        return f"sends a trajectory_msgs/msg/JointTrajectory to {', '.join(self.joints)} on {self.name}"


def _source_text(source: Source) -> str:
    return source.upper() if isinstance(source, str) else str(source).lower()


Binding = Primitive | RosBinding


@dataclass(frozen=True)
class Skill:
    keyword: str
    description: str
    example: str
    params: tuple[Param, ...]
    aliases: tuple[str, ...] = ()
    # The skill that moves the same way in reverse, named in diagnostics when
    # a negative value was written.
    opposite: str | None = None
    # What the skill does on a robot; None only in profiles that never reach one
    # (the backends refuse such a skill with the reason).
    binding: Binding | None = None
    # How explain-back says one statement, e.g. "drive forward {distance}"; empty: worded from `description`.
    say: str = ""
    # A skill run first on this skill's object when the object is out of the arm's reach (`approach`).
    out_of_reach: str | None = None
    # Words a speaker of another language says for the skill, per language code (`ko`), that the
    # recogniser is biased toward; English words are the keyword and aliases.
    words: tuple[tuple[str, tuple[str, ...]], ...] = ()

    def words_in(self, language: str) -> tuple[str, ...]:
        return dict(self.words).get(language, ())

    @property
    def primitive(self) -> Primitive | None:
        return self.binding if isinstance(self.binding, Primitive) else None

    @property
    def signature(self) -> str:
        """How the statement is written, e.g. `goto X, Y;`."""
        names = ", ".join(p.name.upper() if p.kind == "number" else "OBJECT" for p in self.params)
        return f"{self.keyword} {names};" if names else f"{self.keyword};"


@dataclass(frozen=True)
class Convention:
    phrase: str
    meaning: str
    task: str
    program: str
    # Other words people say for the phrase ("slightly" for "a little"): read as the phrase before the model
    # and the checks see a task, so they are how it is heard, not what an adapter learned.
    also: tuple[str, ...] = ()

    @property
    def whole_command(self) -> bool:
        """Whether the phrase is a whole command ("look around") rather than an amount ("a little").

        An amount's meaning gives numbers with units and its example task says
        more than the phrase; a whole command is run as its program.
        """
        if not self.program:
            return False
        return self.task.strip() == self.phrase or not _AMOUNT.search(self.meaning)


@dataclass(frozen=True)
class Inability:
    """Something people ask of robots that this one cannot do, so a request for it is refused
    with the reason instead of being translated into the nearest skill it has."""

    what: str  # e.g. "pick things up: it has no arm or gripper"
    phrases: tuple[str, ...]  # lowercase words or phrases that ask for it, e.g. "pick up"

    def asked_in(self, text: str) -> str | None:
        """The phrase of `text` that asks for this, if any."""
        lowered = text.lower()
        return next((p for p in self.phrases if re.search(rf"\b{re.escape(p)}\b", lowered)), None)


@dataclass(frozen=True)
class PartBack:
    """Words that put a part of the robot back as it was ("look straight ahead again" for the head): the
    steps that undo the part's movement come from its skills' opposites, not from the model."""

    part: str  # a noun of the robot's description, e.g. "head"
    phrases: tuple[str, ...]  # lowercase words that end a task by asking for it


@dataclass(frozen=True)
class FrameWay:
    """Words that say which way a point lies from the start along one axis of the workspace ("2 m ahead",
    "1 m to your right"): the checks read a point said so against the plan's drive to a point."""

    axis: str  # "x" or "y", as the workspace names them
    sign: int  # 1 toward the axis's positive end, -1 away
    phrases: tuple[str, ...]  # lowercase words said after the amount, e.g. "in front"


@dataclass(frozen=True)
class Motion:
    """The profile's `[motion]` table."""

    max_linear_speed: float = setting(0.5, above=0.0, doc="m/s")
    max_angular_speed: float = setting(1.0, above=0.0, doc="rad/s")
    max_linear_accel: float = setting(1.0, above=0.0, doc="m/s^2")
    max_angular_accel: float = setting(2.0, above=0.0, doc="rad/s^2")
    max_head_speed: float = setting(1.5, above=0.0, doc="rad/s")
    reach: float = setting(0.8, above=0.0, doc="m, from the base centre to the farthest graspable point")
    standoff: float = setting(0.5, above=0.0, doc="m, where approaching an object stops in front of it")
    timeout_margin: float = setting(5.0, min=0.0, doc="s, added to every step's time budget")
    width: float = setting(0.4, above=0.0, doc="m, across the base: the corridor a straight drive sweeps")


@dataclass(frozen=True)
class _Limits:
    """The profile's `[limits]` table."""

    max_statements: int = setting(64, min=1, doc="a longer program is rejected before it reaches the robot")


@dataclass(frozen=True)
class Profile:
    name: str
    description: str
    skills: tuple[Skill, ...]
    workspace: dict[str, tuple[float, float]]
    max_statements: int
    motion: Motion
    head: dict[str, tuple[float, float]]
    ros: dict[str, Any]
    conventions: tuple[Convention, ...]
    digest: str = field(repr=False)
    cannot: tuple[Inability, ...] = ()
    back: tuple[PartBack, ...] = ()
    frame: tuple[FrameWay, ...] = ()
    # What people call this robot when they speak to it ("robot, look up"): any other name opening a task
    # speaks to someone else.
    called: tuple[str, ...] = ("robot",)
    source: str = field(repr=False, default="")

    def skill(self, keyword: str) -> Skill | None:
        return self._by_keyword().get(keyword)

    @property
    def keywords(self) -> tuple[str, ...]:
        return tuple(s.keyword for s in self.skills)

    def inability(self, text: str) -> tuple[Inability, str] | None:
        """What of this robot's inabilities `text` asks for, with the phrase that asks."""
        for inability in self.cannot:
            phrase = inability.asked_in(text)
            if phrase is not None:
                return inability, phrase
        return None

    def bound_to(self, primitive: str) -> Skill | None:
        """The first skill bound to a robot primitive, to name it in advice."""
        return next((s for s in self.skills if s.primitive is not None and s.primitive.name == primitive), None)

    def alias_target(self, word: str) -> str | None:
        """The skill a common synonym like `move` or `grab` stands for."""
        lowered = word.lower()
        for skill in self.skills:
            if lowered in skill.aliases:
                return skill.keyword
        return None

    def _by_keyword(self) -> dict[str, Skill]:
        cached: dict[str, Skill] | None = self.__dict__.get("_index")
        if cached is None:
            cached = {s.keyword: s for s in self.skills}
            object.__setattr__(self, "_index", cached)
        return cached


def default_profile_path() -> Path:
    return Path(str(resources.files("rsl") / "profiles" / "default.toml"))


def load_profile(path: str | Path | None = None) -> Profile:
    """Load and validate a profile; the default robot when `path` is None."""
    profile_path = Path(path) if path is not None else default_profile_path()
    try:
        raw_bytes = profile_path.read_bytes()
    except OSError as exc:
        raise ProfileError(f"cannot read robot profile {profile_path}: {exc.strerror}") from exc
    return parse_profile(raw_bytes.decode("utf-8"), source=str(profile_path))


def parse_profile(text: str, source: str = "<profile>") -> Profile:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProfileError(f"{source}: not valid TOML: {exc}") from exc
    return _build(data, source)


def _build(data: dict[str, Any], source: str) -> Profile:
    def fail(message: str) -> ProfileError:
        return ProfileError(f"{source}: {message}")

    robot = data.get("robot", {})
    raw_skills = data.get("skills")
    if not isinstance(raw_skills, list) or not raw_skills:
        raise fail("declares no [[skills]]; a robot needs at least one skill")

    workspace = {axis: _pair(data.get("workspace", {}).get(axis, (-10.0, 10.0)), f"workspace.{axis}", fail)
                 for axis in ("x", "y")}
    head = {joint: _pair(data.get("head", {}).get(joint, default), f"head.{joint}", fail)
            for joint, default in (("pan", (-1.5708, 1.5708)), ("tilt", (-0.6, 0.9)))}

    skills: list[Skill] = []
    seen: set[str] = set()
    for index, raw in enumerate(raw_skills, start=1):
        skills.append(_skill(raw, index, workspace, fail))
        if skills[-1].keyword in seen:
            raise fail(f"skill `{skills[-1].keyword}` is declared twice")
        seen.add(skills[-1].keyword)
    for skill in skills:
        if skill.opposite is not None and skill.opposite not in seen:
            raise fail(f"skill `{skill.keyword}`: opposite `{skill.opposite}` is not a skill")
        if skill.out_of_reach is not None and skill.out_of_reach not in seen:
            raise fail(f"skill `{skill.keyword}`: out_of_reach `{skill.out_of_reach}` is not a skill")
        for alias in skill.aliases:
            if alias in seen:
                raise fail(f"alias `{alias}` of `{skill.keyword}` is itself a skill keyword")

    motion = read_settings(Motion, data.get("motion", {}), error=ProfileError, source=source, prefix="motion.",
                           docs="docs/skills.md")

    conventions = tuple(
        Convention(phrase=str(c["phrase"]), meaning=str(c["meaning"]),
                   task=str(c.get("task", "")), program=str(c.get("program", "")),
                   also=_other_words(c, fail))
        for c in data.get("conventions", [])
    )
    convention_phrases = {c.phrase for c in conventions}
    for convention in conventions:
        taken = next((w for w in convention.also if w in convention_phrases), None)
        if taken is not None:
            raise fail(f"[[conventions]] {convention.phrase!r}: `also` word {taken!r} is another convention's "
                       "phrase")
    cannot = []
    for _index, what, phrases in _phrase_tables(data, "cannot", "what", "a sentence", fail):
        for phrase in phrases:
            for skill in skills:
                if phrase in (skill.keyword, *skill.aliases):
                    raise fail(f"[[cannot]] phrase {phrase!r} is a word for the skill `{skill.keyword}`")
        cannot.append(Inability(what=what, phrases=phrases))
    back = []
    parts = sorted(set(part_nouns(str(robot.get("description", ""))).values()))
    for index, part, phrases in _phrase_tables(data, "back", "part", "a part of the robot", fail):
        if part.lower() not in parts:
            raise fail(f"[[back]] #{index}: part {part!r} is not a part the robot's description names "
                       f"(its parts: {', '.join(parts)})")
        back.append(PartBack(part=part.lower(), phrases=phrases))
    frame = []
    for index, toward, phrases in _phrase_tables(data, "frame", "toward", 'an axis\'s end, "+x" or "-y"', fail):
        if len(toward) != 2 or toward[0] not in "+-" or toward[1:] not in workspace:
            raise fail(f"[[frame]] #{index}: toward {toward!r} must be + or - and an axis of the workspace "
                       f"({', '.join(sorted(workspace))}), such as \"+x\"")
        frame.append(FrameWay(axis=toward[1:], sign=1 if toward[0] == "+" else -1, phrases=phrases))
    max_statements = read_settings(_Limits, data.get("limits", {}), error=ProfileError, source=source,
                                   prefix="limits.", docs="docs/skills.md").max_statements

    called = robot.get("called", ["robot"])
    if not isinstance(called, list) or not all(isinstance(w, str) and WORD.fullmatch(w) for w in called):
        raise fail(f"[robot] called must be a list of lower-case words such as [\"robot\", \"robbie\"], "
                   f"not {called!r}")
    return Profile(
        name=str(robot.get("name", Path(source).stem)),
        description=str(robot.get("description", "a robot")),
        skills=tuple(skills),
        workspace=workspace,
        max_statements=max_statements,
        motion=motion,
        head=head,
        ros=dict(data.get("ros", {})),
        conventions=conventions,
        digest=_language_digest(data),
        source=source,
        cannot=tuple(cannot),
        back=tuple(back),
        called=tuple(called),
        frame=tuple(frame),
    )


def part_nouns(description: str) -> dict[str, str]:
    """The robot's parts as its description names them: noun -> the part it belongs to.

    "A robot: a wheeled base, a pan-tilt head with a camera, and a gripper"
    gives base, head and gripper, and the camera as the head's. The base,
    which moves the robot as a whole, is always a part.
    """
    nouns: dict[str, str] = {}
    for piece in re.split(r",|\band\b", description.split(":", 1)[-1]):
        owner, _, sub = piece.partition(" with ")
        owner_words = WORD.findall(owner)
        if not owner_words:
            continue
        part = owner_words[-1]
        nouns[part] = part
        sub_words = WORD.findall(sub)
        if sub_words:
            nouns[sub_words[-1]] = part
    nouns.setdefault(WHOLE, WHOLE)
    return nouns


def _phrase_tables(data: dict[str, Any], table: str, key: str, shape: str,
                   fail: Callable[[str], ProfileError]) -> Iterator[tuple[int, str, tuple[str, ...]]]:
    """Each `[[table]]` entry as (its number, its `key`, its phrases lower-cased); raises on a malformed one."""
    for index, raw in enumerate(data.get(table, []), start=1):
        value, phrases = raw.get(key), raw.get("phrases")
        if (not isinstance(value, str) or not value or not isinstance(phrases, list) or not phrases
                or not all(isinstance(p, str) and p.strip() for p in phrases)):
            raise fail(f"[[{table}]] #{index} needs `{key}` ({shape}) and `phrases` (a list of words)")
        yield index, value, tuple(p.strip().lower() for p in phrases)


# What a skill's statement is and means; bindings, spoken wording and the
# like say how the robot does it or tells it, not what the adapter learned.
_LANGUAGE_KEYS = ("keyword", "description", "example", "aliases", "opposite", "params")


def _other_words(table: dict[str, Any], fail: Callable[[str], ProfileError]) -> tuple[str, ...]:
    """A convention's `also`: lower-case words or phrases, one space between words."""
    also = table.get("also", [])
    if not isinstance(also, list) or not all(isinstance(w, str) and re.fullmatch(r"[a-z]+(?: [a-z]+)*", w)
                                             for w in also):
        raise fail(f"[[conventions]] {table.get('phrase')!r}: `also` must be a list of lower-case words or "
                   f"phrases such as [\"slightly\", \"a tad\"], not {also!r}")
    return tuple(also)


def _language_digest(data: dict[str, Any]) -> str:
    """The digest of the language a profile defines: what an adapter's card pins.

    It covers the robot's name, each skill's statement and meaning, the
    conventions (less the other words they are heard in), the workspace and
    the statement limit: the things the prompt and the training data are
    made of. Rebinding a skill, rewording how it is explained or changing a
    joint limit keeps the adapter; renaming a skill does not.
    """
    language = {
        "robot": data.get("robot", {}).get("name"),
        "skills": [{key: skill.get(key) for key in _LANGUAGE_KEYS} for skill in data.get("skills", [])],
        "conventions": [{k: v for k, v in c.items() if k != "also"} for c in data.get("conventions", [])],
        "workspace": data.get("workspace", {}),
        "limits": data.get("limits", {}),
    }
    return hashlib.sha256(json.dumps(language, sort_keys=True).encode("utf-8")).hexdigest()


def _pair(value: Any, where: str, fail: Any) -> tuple[float, float]:
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        raise fail(f"{where} must be a pair [low, high] of numbers") from None
    if not low < high:
        raise fail(f"{where} must have low < high, got [{low}, {high}]")
    return low, high


def _skill(raw: dict[str, Any], index: int, workspace: dict[str, tuple[float, float]], fail: Any) -> Skill:
    word = raw.get("keyword")
    if not isinstance(word, str) or not SKILL_KEYWORD.match(word) or python_keyword.iskeyword(word):
        raise fail(f"skill #{index}: keyword {word!r} must be a lowercase identifier "
                   "([a-z][a-z0-9_]*) and not a Python keyword")
    params: list[Param] = []
    for p in raw.get("params", []):
        kind = p.get("kind")
        if kind not in ("number", "object"):
            raise fail(f"skill `{word}`: parameter kind {kind!r} must be \"number\" or \"object\"")
        axis = p.get("axis")
        if axis is not None and axis not in workspace:
            raise fail(f"skill `{word}`: axis {axis!r} must be one of {sorted(workspace)}")
        low = p.get("min")
        high = p.get("max")
        if axis is not None:
            low, high = workspace[axis]
        params.append(Param(name=str(p.get("name", f"arg{len(params) + 1}")), kind=kind,
                            unit=str(p.get("unit", "")),
                            min=None if low is None else float(low),
                            max=None if high is None else float(high), axis=axis))
    aliases = tuple(str(a).lower() for a in raw.get("aliases", []))
    words = raw.get("words", {})
    if not isinstance(words, dict) or not all(
            isinstance(spoken, list) and spoken and all(isinstance(w, str) and w.strip() for w in spoken)
            for spoken in words.values()):
        raise fail(f"skill `{word}`: `words` must map a language code to the words said for the skill, "
                   f"e.g. words = {{ ko = [\"앞으로\"] }}")
    binding = None
    if "binding" in raw:
        binding = _binding(raw["binding"], word, tuple(params), lambda m: fail(f"skill `{word}`: binding {m}"))
    return Skill(keyword=word, description=str(raw.get("description", "")),
                 example=str(raw.get("example", f"{word};")), params=tuple(params), aliases=aliases,
                 opposite=raw.get("opposite"), binding=binding,
                 say=str(raw.get("say", "")), out_of_reach=raw.get("out_of_reach"),
                 words=tuple((language, tuple(spoken)) for language, spoken in words.items()))


def _binding(raw: Any, word: str, params: tuple[Param, ...], fail: Any) -> Binding:
    if not isinstance(raw, dict):
        raise fail("must be a table, e.g. { primitive = \"drive\", sign = 1 } or "
                   "{ ros = \"trigger\", service = \"/dock\" }")
    if ("primitive" in raw) == ("ros" in raw):
        raise fail("needs exactly one of `primitive` (one of "
                   f"{', '.join(PRIMITIVES)}) or `ros` (one of {', '.join(ROS_BINDINGS)})")
    if "primitive" in raw:
        return _primitive(raw, params, fail)
    return _ros_binding(raw, params, fail)


def _primitive(raw: dict[str, Any], params: tuple[Param, ...], fail: Any) -> Primitive:
    _only(raw, {"primitive", "sign"}, fail)
    name = raw["primitive"]
    if name not in PRIMITIVES:
        raise fail(f"primitive {name!r} is not one of {', '.join(PRIMITIVES)}; a skill the robot does "
                   f"another way takes a `ros` binding ({', '.join(ROS_BINDINGS)})")
    wanted = PRIMITIVES[name]
    got = tuple((p.kind, p.unit if p.kind == "number" else "") for p in params)
    if got != wanted:
        shape = ", ".join(f"{kind} in {unit}" if unit else kind for kind, unit in wanted) or "no parameters"
        declared = ", ".join(f"{p.name} ({p.kind} in {p.unit})" if p.unit else f"{p.name} ({p.kind})"
                             for p in params)
        raise fail(f"primitive `{name}` takes {shape}; the skill declares {declared or 'none'}")
    if name == "navigate" and sorted(str(p.axis) for p in params) != ["x", "y"]:
        raise fail("primitive `navigate` needs one parameter with axis = \"x\" and one with axis = \"y\"")
    sign = raw.get("sign")
    if name in SIGNED_PRIMITIVES:
        if sign not in (1, -1) or isinstance(sign, bool):
            raise fail(f"primitive `{name}` needs sign = 1 or sign = -1 ({_SIGN_MEANING[name]})")
    elif sign is not None:
        raise fail(f"primitive `{name}` has no direction, so no sign")
    return Primitive(name=name, sign=float(sign if sign is not None else 1))


_SIGN_MEANING = {"drive": "-1 drives backward", "turn": "+1 turns left", "pan": "+1 pans left",
                 "tilt": "+1 tilts up"}


def _ros_binding(raw: dict[str, Any], params: tuple[Param, ...], fail: Any) -> RosBinding:
    kind = raw["ros"]
    if kind not in ROS_BINDINGS:
        raise fail(f"ros {kind!r} is not one of {', '.join(ROS_BINDINGS)}")
    where = "service" if kind in ("trigger", "setbool") else "topic"
    allowed = {"ros", where, *{"topic": ("type", "fields"), "trigger": (), "setbool": ("data",),
                               "joint_trajectory": ("joints", "positions", "duration")}[kind]}
    _only(raw, allowed, fail)
    name = raw.get(where)
    if not isinstance(name, str) or not _ROS_NAME.match(name):
        raise fail(f"`{where}` must be a ROS 2 name such as \"/dock\", got {name!r}")
    names = {p.name for p in params}

    def source(value: Any, what: str) -> Source:
        if isinstance(value, str):
            if value not in names:
                raise fail(f"{what} takes the parameter {value!r}, which the skill does not declare "
                           f"(its parameters: {', '.join(sorted(names)) or 'none'})")
            return value
        if isinstance(value, bool | int | float):
            return value if isinstance(value, bool) else float(value)
        raise fail(f"{what} must be a parameter's name or a constant, got {value!r}")

    def all_used(sources: list[Source], into: str) -> None:
        unused = names - {s for s in sources if isinstance(s, str)}
        if unused:
            raise fail(f"does not send the parameter(s) {', '.join(sorted(unused))}; {into}")

    if kind == "topic":
        message_type = raw.get("type")
        if not isinstance(message_type, str) or not _MESSAGE_TYPE.match(message_type):
            raise fail(f"`type` must be a message type such as \"std_msgs/msg/Float64\", got {message_type!r}")
        raw_fields = raw.get("fields", {})
        if not isinstance(raw_fields, dict):
            raise fail("`fields` must map message fields to parameters, e.g. { data = \"level\" }")
        fields = []
        for path, value in raw_fields.items():
            if not _FIELD_PATH.match(path):
                raise fail(f"field {path!r} must be a field path such as \"data\" or \"linear.x\"")
            fields.append((path, source(value, f"field `{path}`")))
        all_used([v for _, v in fields], "map each to a message field")
        return RosBinding(kind=kind, name=name, message_type=message_type, fields=tuple(fields))
    if kind == "trigger":
        all_used([], "a Trigger request carries none, so declare params = []")
        return RosBinding(kind=kind, name=name)
    if kind == "setbool":
        data = raw.get("data")
        if not isinstance(data, bool):
            raise fail("`data` must be true or false, the SetBool request's value")
        all_used([], "a SetBool request carries only its constant `data`, so declare params = []")
        return RosBinding(kind=kind, name=name, data=data)
    joints = raw.get("joints")
    positions = raw.get("positions")
    if (not isinstance(joints, list) or not joints
            or not all(isinstance(j, str) and IDENTIFIER.match(j) for j in joints)):
        raise fail(f"`joints` must be a list of joint names, got {joints!r}")
    if not isinstance(positions, list) or len(positions) != len(joints):
        raise fail(f"`positions` must give one position per joint ({len(joints)}), got {positions!r}")
    sources = [source(p, f"the position of `{j}`") for j, p in zip(joints, positions, strict=True)]
    all_used(sources, "give each as a joint's position")
    objects = [p.name for p in params if p.kind == "object"]
    if objects:
        raise fail(f"a joint position must be a number, and {', '.join(objects)} is an object")
    duration = raw.get("duration", 1.0)
    if isinstance(duration, bool) or not isinstance(duration, int | float) or duration < 0:
        raise fail(f"`duration` must be seconds >= 0 (the trajectory point's time_from_start), got {duration!r}")
    return RosBinding(kind=kind, name=name, joints=tuple(joints), positions=tuple(sources),
                      duration=float(duration))


def _only(raw: dict[str, Any], allowed: set[str], fail: Any) -> None:
    unknown = sorted(set(raw) - allowed)
    if unknown:
        raise fail(f"has unknown key(s) {', '.join(unknown)}; this form takes {', '.join(sorted(allowed))}")
