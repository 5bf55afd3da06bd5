"""The words of a robot, read from its profile: which part each skill moves and the words for it.

The checks between a task and its plan (agent/translate/meaning.py) read
a task through these: the parts are the nouns of the robot's description
(see `rsl.profile.part_nouns`), a part's words are its skills' keywords,
aliases and the verbs of their descriptions, the direction words are what
tell a skill from its `opposite`, and the conventions give the numbers
that stand in for vague amounts. No skill keyword is named below.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

from agent.translate.clauses import SHAPES
from agent.translate.names import FUNCTION_WORDS
from rsl.compiler import compile_program
from rsl.plan import ObjectRef, Quantity
from rsl.profile import WHOLE, WORD, Profile, part_nouns

NUMBER_UNIT = re.compile(r"(?<![\w.])(-?\d*\.?\d+)(?: (m|rad)\b)?")
_FIRST_CLAUSE = re.compile(r"[.;]")


@dataclass(frozen=True)
class Vocabulary:
    """What the checks know of a robot's words, built once per profile by `vocabulary`."""

    parts: dict[str, str]  # skill keyword -> part ("base", "head", "gripper")
    part_words: dict[str, frozenset[str]]  # part -> words that name it or its skills, unshared
    directions: tuple[tuple[str, frozenset[str], str, frozenset[str]], ...]  # (skill, way, opposite, way)
    convention_numbers: dict[str, frozenset[float]]  # unit -> values the conventions use
    conventions: tuple[ConventionReading, ...]
    coordinates: frozenset[str]  # skills whose numbers are positions, not amounts
    skill_words: frozenset[str]  # keywords, aliases and direction words: never an object's name
    noun_parts: dict[str, str]  # a noun of the robot's description ("camera") -> its part ("head")
    opposites: dict[str, str]  # skill keyword -> its opposite, both ways
    step_words: dict[str, frozenset[str]]  # skill keyword -> the words that ask for that step
    way_skills: dict[str, frozenset[str]]  # way ("left") -> the skills that go it (turnleft, lookleft)
    base_ways: frozenset[str]  # the ways of the skills that move the robot as a whole ("left", "back")
    # Any word of a skill and the first word of each whole command ("fetch", "explore"): a word that asks
    # for a step.
    asking_words: frozenset[str]
    part_verbs: frozenset[str]  # the words of parts other than the base that are no noun ("look", "tilt")
    known_words: frozenset[str]  # what a verb the profile does not list is not: its words and closed-class words
    way_and_amount: re.Pattern[str]  # a way, then a number or a convention's amount ("back a little")
    # The first word of a whole command that is no skill's word ("face" of "face behind") -> the parts
    # its program moves.
    command_verbs: dict[str, frozenset[str]]
    # What goes which way when no way is said: from each convention whose example task says none and whose
    # program goes one way ("spin in a full circle": turnleft 6.2832).
    unsaid_ways: tuple[UnsaidWay, ...]
    past_forms: frozenset[str]  # the skill words' regular past forms ("turned", "grabbed")
    # An amount in metres and the way from the start it is said to lie ("2 m to your right"), from the
    # profile's [[frame]]; and each way's phrase -> (axis, sign).
    point_offset: re.Pattern[str]
    frame: dict[str, tuple[str, int]]
    # skill keyword -> the skill that brings the robot to the thing first (`out_of_reach`: grasp -> approach)
    reached_by: dict[str, str]
    # Words of going to a place: the words of those skills and of the base's distance skills, less ways.
    going_words: frozenset[str]
    # Amounts said in words, which the normalizer leaves as words: each amount convention's phrase and other
    # words, split ("a", "little"), ("slightly",).
    word_amounts: frozenset[tuple[str, ...]]


@dataclass(frozen=True)
class UnsaidWay:
    """A convention's one way, taken when a task says none: a step of `against` by one of `amounts` went
    the other way than `way`, the skill of the convention's example `task`."""

    against: str
    way: str
    amounts: dict[str, frozenset[float]]
    task: str


@dataclass(frozen=True)
class ConventionReading:
    """A profile convention as the checks read it."""

    phrase: str
    words: tuple[str, ...]
    meaning: str
    amounts: dict[str, frozenset[float]]  # unit -> the values it stands for
    # An amount that stands in when nothing is said ("no amount given"): its phrase is not in its own task.
    default: bool
    skills: frozenset[str]  # the skills of its example program
    whole: bool  # a whole command ("look around"), run as its program, not an amount of another step
    # Consecutive steps of its program that act on one object (approach X; grasp X).
    same_object: frozenset[tuple[str, str]]


def skill_words(profile: Profile) -> frozenset[str]:
    """The words of the robot's skills (keywords, aliases, directions): never a thing's name."""
    return vocabulary(profile).skill_words


def skill_parts(profile: Profile) -> dict[str, str]:
    """Which part of the robot each skill moves: the part its description's first clause names.

    The parts are the nouns of the robot's description ("a wheeled base, a
    pan-tilt head with a camera, and a gripper"); a part "with" another (the
    camera) belongs to it. A skill naming none moves the robot as a whole.
    """
    return dict(vocabulary(profile).parts)


def _build_vocabulary(profile: Profile) -> Vocabulary:
    nouns = part_nouns(profile.description)
    parts: dict[str, str] = {}
    words: dict[str, set[str]] = {}
    for skill in profile.skills:
        clause = _FIRST_CLAUSE.split(skill.description, 1)[0].lower()
        named = [nouns[w] for w in WORD.findall(clause) if w in nouns]
        part = named[0] if named else WHOLE
        parts[skill.keyword] = part
        verb = WORD.findall(clause)[:1]
        words.setdefault(part, set()).update({skill.keyword, *skill.aliases, *verb})
    for noun, part in nouns.items():
        words.setdefault(part, set()).add(noun)
    # A shape ("walk a square") is traced by driving.
    words.setdefault(WHOLE, set()).update(SHAPES)
    # A word several parts share ("right" in turnright and lookright) tells no part apart.
    counted: dict[str, int] = {}
    for found in words.values():
        for word in found:
            counted[word] = counted.get(word, 0) + 1
    for keyword, part in parts.items():
        for other, other_part in parts.items():
            if other_part == part:
                continue
            for word in list(words[part]):
                if len(word) >= 2 and word != keyword and word in other and word not in words[other_part]:
                    counted[word] = counted.get(word, 0) + 1
    directions = []
    for skill in profile.skills:
        opposite = profile.skill(skill.opposite) if skill.opposite else None
        if opposite is not None and skill.keyword < opposite.keyword:
            mine, theirs = _difference(skill.keyword, opposite.keyword)
            # "for" tells forward from backward but is no direction a person says; the keyword is.
            mine = mine if mine in skill.aliases else skill.keyword
            theirs = theirs if theirs in opposite.aliases else opposite.keyword
            directions.append((skill.keyword, frozenset({mine}), opposite.keyword, frozenset({theirs})))
    # A direction ("up" in "pick up the cup") says which way, not which part.
    direction_words = {w for d in directions for w in (*d[1], *d[3])}
    part_words = {p: frozenset(w for w in ws if counted[w] == 1 and "_" not in w and w not in direction_words)
                  for p, ws in words.items()}
    # "pan left then right" says the head's ways in the words the base's turns are told apart by. The
    # keyword itself is no way: "look" would be said of both, as its inflections' prefix.
    ways = []
    for skill_keyword, mine_words, opposite_keyword, theirs_words in directions:
        mine_raw, theirs_raw = _difference(skill_keyword, opposite_keyword)
        ways.append((skill_keyword, frozenset({mine_raw} & direction_words) or mine_words,
                     opposite_keyword, frozenset({theirs_raw} & direction_words) or theirs_words))

    coordinates = frozenset(s.keyword for s in profile.skills if any(p.is_coordinate for p in s.params))
    numbers: dict[str, set[float]] = {}
    conventions = []
    for convention in profile.conventions:
        plan = compile_program(convention.program, profile).plan if convention.program else None
        values: dict[str, set[float]] = {}
        for command in plan or ():
            if command.skill in coordinates:
                continue
            for arg in command.args:
                if isinstance(arg, Quantity):
                    values.setdefault(arg.unit, set()).add(abs(arg.value))
        for value, unit in NUMBER_UNIT.findall(convention.meaning):
            if unit:
                values.setdefault(unit, set()).add(abs(float(value)))
        for unit, unit_values in values.items():
            numbers.setdefault(unit, set()).update(unit_values)
        whole = convention.whole_command
        objects = [(c.skill, tuple(a.name for a in c.args if isinstance(a, ObjectRef))) for c in plan or ()]
        same_object = frozenset((a, b) for (a, x), (b, y) in itertools.pairwise(objects) if x and x == y)
        conventions.append(ConventionReading(
            phrase=convention.phrase, words=tuple(WORD.findall(convention.phrase.lower())),
            meaning=convention.meaning, amounts={u: frozenset(v) for u, v in values.items()},
            default=not whole and convention.phrase not in convention.task,
            skills=frozenset(c.skill for c in plan or ()), whole=whole, same_object=same_object))
    opposites = {s.keyword: s.opposite for s in profile.skills if s.opposite}
    opposites.update({o: k for k, o in list(opposites.items())})
    # A way ("right") or a short word ("go", "up") asks for no step of its own.
    step_words = {s.keyword: frozenset(w for w in (s.keyword, *s.aliases,
                                                   *WORD.findall(_FIRST_CLAUSE.split(s.description, 1)[0].lower())[:1])
                                       if len(w) >= 4 and "_" not in w and w not in direction_words)
                  for s in profile.skills}
    way_skills: dict[str, set[str]] = {}
    for skill_keyword, mine_words, opposite_keyword, theirs_words in ways:
        for keyword, said in ((skill_keyword, mine_words), (opposite_keyword, theirs_words)):
            for way in said:
                way_skills.setdefault(way, set()).add(keyword)
    skill_word_set = frozenset({w for ws in words.values() for w in ws} - set(nouns) | direction_words)
    known_words = skill_word_set | frozenset(nouns) | FUNCTION_WORDS
    command_verbs: dict[str, set[str]] = {}
    for c in conventions:
        if c.whole and c.words and c.words[0] not in known_words:
            command_verbs.setdefault(c.words[0], set()).update(parts.get(k, WHOLE) for k in c.skills)
    unsaid_ways = []
    for convention, reading in zip(profile.conventions, conventions, strict=True):
        gone = [k for k in reading.skills if k in opposites and opposites[k] not in reading.skills]
        if len(gone) == 1 and not set(WORD.findall(convention.task)) & way_skills.keys():
            unsaid_ways.append(UnsaidWay(opposites[gone[0]], gone[0], reading.amounts, convention.task))
    reached_by = {s.keyword: s.out_of_reach for s in profile.skills if s.out_of_reach}
    distance_skills = [s for s in profile.skills if parts.get(s.keyword, WHOLE) == WHOLE
                       and s.keyword not in coordinates and any(p.unit == "m" for p in s.params)]
    going_words = frozenset(w for s in profile.skills if s.keyword in reached_by.values() or s in distance_skills
                            for w in (*step_words[s.keyword], *s.aliases)
                            if w.isalpha() and w not in direction_words)
    frame = {phrase: (way.axis, way.sign) for way in profile.frame for phrase in way.phrases}
    # The longest phrase first, so "to your right" is read whole rather than as "right" alone.
    frame_phrases = "|".join(re.escape(p) for p in sorted(frame, key=len, reverse=True)) or "(?!)"
    amount_phrases = "|".join(re.escape(c.phrase) for c in conventions if c.amounts and not c.whole and not c.default)
    return Vocabulary(parts=parts, part_words=part_words, directions=tuple(ways),
                       convention_numbers={u: frozenset(v) for u, v in numbers.items()},
                       conventions=tuple(conventions), coordinates=coordinates,
                       skill_words=skill_word_set, noun_parts=nouns, opposites=opposites,
                       step_words=step_words, way_skills={w: frozenset(k) for w, k in way_skills.items()},
                       base_ways=frozenset(w for skill, mine, _opposite, theirs in ways
                                           if parts.get(skill, WHOLE) == WHOLE for w in mine | theirs),
                       asking_words=skill_word_set | {c.words[0] for c in conventions if c.whole and c.words},
                       part_verbs=frozenset(w for p, ws in part_words.items() if p != WHOLE for w in ws) - set(nouns),
                       known_words=known_words,
                       way_and_amount=re.compile(rf"\s+([a-z]+)\s+(?:\d*\.?\d+|{amount_phrases})\b"),
                       command_verbs={w: frozenset(ps) for w, ps in command_verbs.items()},
                       unsaid_ways=tuple(unsaid_ways), past_forms=_past_forms(skill_word_set),
                       point_offset=re.compile(rf"(?<![\w.])(\d*\.?\d+) m ({frame_phrases})\b"),
                       frame=frame, reached_by=reached_by, going_words=going_words,
                       word_amounts=frozenset(tuple(p.split()) for c in profile.conventions if not c.whole_command
                                              for p in (c.phrase, *c.also)))


def _past_forms(words: frozenset[str]) -> frozenset[str]:
    """The regular past forms of `words`: "turned", "moved", "grabbed"."""
    forms = set()
    for word in words:
        forms |= {word + "ed", word + "d"}
        if len(word) >= 3 and word[-1] not in "aeiouwxy" and word[-2] in "aeiou" and word[-3] not in "aeiou":
            forms.add(word + word[-1] + "ed")
    return frozenset(forms)


_VOCABULARIES: dict[tuple[str, str], Vocabulary] = {}


def vocabulary(profile: Profile) -> Vocabulary:
    """The words of `profile`'s robot, read once and kept."""
    # The language digest leaves out the robot's description, which an adapter never learned but the
    # parts are read from.
    key = (profile.digest, profile.description)
    found = _VOCABULARIES.get(key)
    if found is None:
        found = _VOCABULARIES[key] = _build_vocabulary(profile)
    return found


def _difference(a: str, b: str) -> tuple[str, str]:
    """What tells two keywords apart: turnleft/turnright -> left/right; forward/backward stay whole."""
    start = 0
    while start < min(len(a), len(b)) and a[start] == b[start]:
        start += 1
    end = 0
    while end < min(len(a), len(b)) - start and a[-1 - end] == b[-1 - end]:
        end += 1
    start = start if start >= 3 else 0
    end = end if end >= 3 else 0
    return a[start:len(a) - end], b[start:len(b) - end]
