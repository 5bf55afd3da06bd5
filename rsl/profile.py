"""The robot profile: the one source of truth for a robot's skills.

A profile is a TOML file. Everything that knows about skills (the parser,
diagnostics, grammar export, prompt, docs, training data and the backends'
speed limits) reads it from here, so adding a skill is a data change.
"""

from __future__ import annotations

import hashlib
import keyword as python_keyword
import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Literal

IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
SKILL_KEYWORD = re.compile(r"[a-z][a-z0-9_]*\Z")
_AMOUNT = re.compile(r"\d\s*[a-z]+\b")

ParamKind = Literal["number", "object"]


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
class Skill:
    keyword: str
    description: str
    example: str
    params: tuple[Param, ...]
    aliases: tuple[str, ...] = ()
    # The skill that moves the same way in reverse, named in diagnostics when
    # a negative value was written.
    opposite: str | None = None
    # How explain-back says one statement, e.g. "drive forward {distance}"; empty: worded from `description`.
    say: str = ""
    # A skill run first on this skill's object when the object is out of the arm's reach (`approach`).
    out_of_reach: str | None = None
    # How the skill moves the base, for checks before motion: `drives` is the bearing (degrees from where
    # the robot faces) of a straight drive by its distance; `turns` +1 turns left by its angle, -1 right.
    drives: float | None = None
    turns: float | None = None

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
class Motion:
    max_linear_speed: float = 0.5
    max_angular_speed: float = 1.0
    max_linear_accel: float = 1.0
    max_angular_accel: float = 2.0
    max_head_speed: float = 1.5
    reach: float = 0.8
    standoff: float = 0.5
    timeout_margin: float = 5.0
    width: float = 0.4  # m, across the base: the corridor a straight drive sweeps


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
    source: str = field(repr=False, default="")

    def skill(self, keyword: str) -> Skill | None:
        return self._by_keyword().get(keyword)

    @property
    def keywords(self) -> tuple[str, ...]:
        return tuple(s.keyword for s in self.skills)

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
    return _build(data, text, source)


def _build(data: dict[str, Any], text: str, source: str) -> Profile:
    def fail(message: str) -> ProfileError:
        return ProfileError(f"{source}: {message}")

    robot = data.get("robot", {})
    raw_skills = data.get("skills")
    if not isinstance(raw_skills, list) or not raw_skills:
        raise fail("declares no [[skills]]; a robot needs at least one skill")

    workspace = {axis: _pair(data.get("workspace", {}).get(axis, (-10.0, 10.0)), f"workspace.{axis}", fail)
                 for axis in ("x", "y")}
    head = {joint: _pair(data.get("head", {}).get(joint, default), f"head.{joint}", fail)
            for joint, default in (("pan", (-1.57, 1.57)), ("tilt", (-0.6, 0.9)))}

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

    motion_fields = Motion.__dataclass_fields__
    raw_motion = data.get("motion", {})
    unknown = set(raw_motion) - set(motion_fields)
    if unknown:
        raise fail(f"unknown [motion] settings: {', '.join(sorted(unknown))}")
    motion = Motion(**{k: float(v) for k, v in raw_motion.items()})

    conventions = tuple(
        Convention(phrase=str(c["phrase"]), meaning=str(c["meaning"]),
                   task=str(c.get("task", "")), program=str(c.get("program", "")))
        for c in data.get("conventions", [])
    )
    limits = data.get("limits", {})
    max_statements = int(limits.get("max_statements", 64))
    if max_statements < 1:
        raise fail("limits.max_statements must be at least 1")

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
        digest=hashlib.sha256(text.encode("utf-8")).hexdigest(),
        source=source,
    )


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
    return Skill(keyword=word, description=str(raw.get("description", "")),
                 example=str(raw.get("example", f"{word};")), params=tuple(params), aliases=aliases,
                 opposite=raw.get("opposite"),
                 say=str(raw.get("say", "")), out_of_reach=raw.get("out_of_reach"),
                 drives=None if raw.get("drives") is None else float(raw["drives"]),
                 turns=None if raw.get("turns") is None else float(raw["turns"]))
