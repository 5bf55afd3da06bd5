"""Checks between what a person said and the plan that verified: does it do what was asked?

A program can be grammatical and in range and still not be what was meant:
a polite closing that drives 1 m, a request about the head that turns the
base, 90 degrees said and 688 degrees planned. Each check here compares
the normalized task with the plan and, when they disagree, gives a reason a
person can read ("you said 90° but the plan turns 688°").

Everything is derived from the robot profile, through the words
agent/translate/vocabulary.py reads from it: which skills move the base or
the head, the words for each part, the direction words and the numbers
that stand in for vague amounts ([[conventions]]). No skill keyword is
named below.
"""

from __future__ import annotations

import itertools
import math
import re
from collections import Counter
from collections.abc import Collection, Iterable
from dataclasses import dataclass

from agent.corrections import MARKERS
from agent.translate.clauses import SHAPES
from agent.translate.explain import quantity, say
from agent.translate.names import DETERMINERS, FUNCTION_WORDS, NOT_NAMES
from agent.translate.people import names_a_person
from agent.translate.vocabulary import NUMBER_UNIT, WHOLE, WORD, ConventionReading, Vocabulary, vocabulary
from rsl.plan import Command, ObjectRef, Plan, Quantity
from rsl.profile import Profile

_COUNT = re.compile(r"\b(\d+) times\b")
# A step said after a count: "3 times then turn right", "twice and look up".
_STEP_AFTER = re.compile(r",?\s*(?:and\s+then|and|then)\s+[a-z]")
# The word that starts a clause, or follows a conjunction, a subject or a modal ("so head over", "if you
# could head over"); the word itself is not consumed, so "and then head" finds "head" after "then".
_CLAUSE_START = re.compile(r"(?:^|[,.;]|\b(?:and|then|so|but|or|you|to|can|could|would|will|should|must)\b)"
                           r"\s*(?=([a-z]+))")
# A pause a speaker may take before correcting: "wait, no", "hang on, I meant".
_HESITATIONS = "wait|hang on|hold on"
# What a self-correction takes back: the number or the word right before its markers ("no, make that"),
# when another follows. A hesitation before the markers is part of them.
_CORRECTED = (rf"(?:,?\s+(?:{_HESITATIONS}))?(?:,?\s+(?:{'|'.join(MARKERS)}))+,?\s+"
              r"(?:(?:the|a|an) )?")
# The number may be said again with its step ("1 m, no, back up 2 m"), in its unit or bare; a word of
# sequence between makes the second another step.
_TAKEN_BACK_NUMBER = re.compile(rf"(?<![\w.])(-?\d*\.?\d+)(?: (m|rad)\b)?{_CORRECTED}"
                                r"(?=(?:(?!(?:and|then|after|next|also)\b)[a-z']+,? ){0,4}?-?\d*\.?\d+"
                                r"(?(2) \2\b|(?! (?:m|rad)\b)))")
_TAKEN_BACK_WORD = re.compile(rf"\b([a-z]+){_CORRECTED}([a-z]+)")
# An amount taken back by a marker and said again, with its step or without ("back up 1 m, scratch that,
# back up 0.5 m").
_CORRECTED_AMOUNT = re.compile(rf"(?<![\w.])(\d*\.?\d+) (m|rad){_CORRECTED}((?:[a-z']+,? ){{0,4}}?)(\d*\.?\d+) \2\b")
_NEXT_WORD = re.compile(r"\s+([a-z]+)")
_CORRECTION = re.compile(_CORRECTED)
# A correction, or a pause alone, between a way and its opposite: "left, hang on, right", "back, I mean
# forward", "left, scratch that, pan it right".
_WAY_CORRECTION = re.compile(rf"(?:,?\s+(?:{_HESITATIONS}|{'|'.join(MARKERS)}))+,?\s+")
# "would you mind turning left", "before grabbing the cup": the "-ing" word after "mind", "before" or
# "after" asks for the act. Elsewhere an "-ing" form may tell what was done ("nice job turning left").
_ASKED_DOING = re.compile(r"\b(mind|before|after) ([a-z]{3,}?)ing\b")
# "take a look", "get a picture": the verb only carries the noun, so it asks nothing of the gripper.
_LIGHT_VERB = re.compile(r"\b(?:take|get|grab)\s+(?=(?:a|another)\s+(?:(?:quick|little|good|close)\s+)?"
                         r"(?:look|peek|glance|picture|photo|snapshot|pic)\b)")
# "take a left", "take a sharp right": the verb carries a way of the base, so it asks nothing of the gripper.
_TAKE_A_WAY = re.compile(r"\btake\s+(?=(?:a|the)\s+(?:(?:sharp|hard|quick|slight)\s+)?([a-z]+)\b)")
# A point said whole: two numbers joined by a comma ("the point 3, -2").
_POINT = re.compile(r"(?<![\w.])(-?\d*\.?\d+), (-?\d*\.?\d+)(?![\w.])")
# Two amounts in one unit with only a comma and a few words between: the second may correct the first
# in words no marker lists ("90 degrees, correction, 45 degrees").
_RESTATED = re.compile(r"(?<![\w.])(\d*\.?\d+) (m|rad),((?: [a-z']+){0,3}?),? (\d*\.?\d+) \2\b")
# Words that ask for a step once more without a count.
_AGAIN_WORDS = ("again", "another", "more")
_AGAIN = re.compile(rf"\b(?:{'|'.join(_AGAIN_WORDS)}|repeat\w*|twice)\b")
# A clause that only asks for what came before once more ("and repeat that once more", "do it again",
# "same again"): its words, and those of them that ask.
_REPEAT_WORDS = frozenset({"and", "then", "now", "do", "that", "it", "this", "the", "all", "of", "whole", "thing",
                           "please", "repeat", "same", "again", "once", "more", "1", "one", "time"})
_REPEAT_ASKS = frozenset({"repeat", "same", "again", "more"})
_SEQUENCE_WORDS = frozenset({"and", "then", "after", "next", "finally", "times", *_AGAIN_WORDS})
# What negates what follows it up to the end of its clause ("don't move, just look left"), and a part
# kept still ("keep your head still and turn left", "keep your head where it is"). "why don't you look up"
# suggests, and "don't forget to look up" asks, rather than negates.
_NEGATORS = r"don'?t|do not|never|without"
_NEGATION = re.compile(rf"(?<!\bwhy )\b(?:{_NEGATORS}|no|not)\b(?! forget\b)[^,.;]*"
                       r"|\b(?:keep|hold)\s+(?:[a-z]+\s+){0,2}?(?:still|steady|in place|where it is|as it is)\b")
# Taking a step back: "skip the turn", "forget about turning", "don't turn". It reaches to the end of its
# clause or to a word that starts another step ("skip the turn and drive on"); "don't forget to look up"
# asks for the step.
_CANCELLED = re.compile(rf"(?<!\bwhy )\b(?:{_NEGATORS}|skip|cancel|scrap|omit|ignore|leave out"
                        r"|(?<!don't )(?<!dont )(?<!do not )(?<!never )forget)\b(?! forget\b)"
                        r"(?:(?!\b(?:and|then|but|just|instead|only|so|rather)\b)[^,.;])*")
# A way said of where a thing is ("the cup on your right") or of when ("right away"), not which way to go.
_PLACE_OR_TIME = frozenset({"now", "away", "here", "there", "after", "before", "behind", "next", "of", "in", "at",
                            "on", "beside", "by"})
_OWNER = frozenset({"the", "your", "my", "its", "his", "her", "their", "all"})
# A part the task keeps the plan to: "only your head", "with the head only".
_ONLY = (re.compile(r"\bonly (?:with |using )?(?:your |the |its )?([a-z]+)"), re.compile(r"\b([a-z]+) only\b"))
# A question about the robot, asked and left there ("why do you keep looking up"), is no request;
# "why don't you look up" suggests ("don't" is no auxiliary here), and a request after it
# ("what are you waiting for, go forward") is one.
# A question about what was done ("did you go forward earlier") is no request either; "can you",
# "would you" and "do you mind" ask for the act, so only the past and perfect auxiliaries count, and
# "can you see" asks whether the robot sees, not for it to look.
# "How far", "how long" and the like ask about an amount, never for a step; a decimal point ends no clause.
_QUESTION = re.compile(r"^(?:[a-z]+, )?(?:(?:why|what|where|when|who|which|how) "
                       r"(?:do|does|did|is|are|was|were|have|has|had|can|could|will|would|should)"
                       r"|how (?:far|long|much|many|fast|often|high|low)|is it possible"
                       r"|(?:did|was|were|have|has|had) (?:you|it|we|they|i)|(?:can|could|do) you see)\b(?!')"
                       r"(?!.*\bthen\b)(?:[^,;.]|\.(?=\d))*$")
# An order told of, imagined or planned for later is not given now: "she told me to turn left",
# "my dad always said, turn around", "you should have gone back", "if I asked you to fetch it",
# "tomorrow we'll get it to fetch the mail", "hypothetically, if you had to fetch the cup", "i wish you could
# turn faster". "Like I said, turn left" repeats an order, so "I" is left out.
_FRAMED = re.compile(r"\b(?:told|tells?|asked|asks?|wants?|wanted) (?:me|us|him|her|them) to\b"
                     r"|\b(?!i\b)[a-z]+ (?:(?:always|once|just|never|also) )?(?:said|says)\b"
                     r"|\b(?:should|could|would|might|must)(?:n'?t)? (?:have|'ve)\b|\b(?:should|could)'ve\b"
                     r"|\bif i (?:asked|told|wanted|said)\b|\bwhat (?:would|will) happen if\b|\bwhat (?:happens )?if\b"
                     r"|\b(?:hypothetically|in theory|suppos(?:e|ing)|imagine|if you had to|i wish|eventually)\b"
                     r"|\b(?:we|i)(?:'ll| will) (?:have|get|teach) you\b"
                     r"|\b(?:later|tomorrow|tonight|next (?:week|time|month|year)|some ?(?:day|time)|one day"
                     r"|in the future)\b")
# The robot itself named as what moves ("turn yourself", "swivel the whole robot", "on your wheels") asks for
# the part that moves it as a whole; a vocative ("robot, look up") names no thing to move.
_SELF = re.compile(r"\b(?:yourself|(?:your|the|its) (?:whole |entire )?(?:body|self|robot|chassis|wheels)"
                   r"|whole (?:robot|thing|body)|on (?:your |its )?wheels)\b")
# What the speaker is about to do is no order: "I'm going to turn left at the roundabout". "I'm going to ask
# you to turn left" and "I'm going to need you to" still ask.
_NARRATED = re.compile(r"\b(?:i|we)(?:'m| am|'re| are) (?:going to|gonna|about to) "
                       r"(?!(?:ask|get|have|need|want|make|let|tell)\b)")
# ... nor what the speaker did, told with a skill's word in the past: "we just turned left".
_DONE_BY_SPEAKER = re.compile(r"^(?:[a-z]+, )?(?:i|we) (?:just |already |then )?([a-z]+ed)\b")
# What the robot or someone else did, told at the start of a clause, perhaps after when: "yesterday you
# turned left twice", "in the demo, the robot grabbed the ball". After "after", "when" or "like" the past
# is only a time or a manner ("after you turned left, go forward"), so only a clause's first words count.
_DONE_BY_SOMEONE = re.compile(r"(?:^|, |\band |\bbut )(?:(?:yesterday|earlier|today|before|last [a-z]+"
                              r"|this [a-z]+|on [a-z]+day)?,? )?(?:the (?:other )?)?(?:you|it|he|she|they|robot)"
                              r" (?:just |already |then |also |once |never |always |[a-z]+ly )?([a-z]+ed)\b")
# Whom a task is said to: one word and a comma at its start, after at most one greeting ("hey mia, look up"),
# or a comma and one word at its end ("turn left at the lights, dad").
_CALLED = re.compile(r"^(?:(?:hey|hi|hello|oi|ok|okay|yo),? )?([a-z]+), |, ([a-z]+)$")
# Everything said so far called off at the end, with no step asked after it: "turn left, actually, never
# mind", "go to the door and, actually, don't bother", "look up, no, cancel that".
_CALLED_OFF = re.compile(r"\b(?:never ?mind|(?:forget|scrap|cancel|scratch|ignore) (?:about )?(?:it|that|this|all"
                         r"(?: of)?(?: that| this| it)?|everything|the whole thing)|ignore me|don'?t bother"
                         r"|not now|as you were|(?:wait|actually|no),? don'?t(?=,|$)|leave it(?=,|$))\b")
# A check that finds the words asked for nothing now: such a plan is refused, not put to the person.
ASKS_NOTHING = frozenset({"framed", "narrated", "question", "called-off"})
# A check whose steps nobody asked for: a step taken back, a thing corrected to another, the robot's own
# part taken for a thing. Leaving those steps out may leave just what was asked.
NOT_ASKED = frozenset({"cancelled", "corrected", "corrected-way", "own-part"})
# Words that tell what a thing is near ("the keys by the front door", "the cup in front of your camera"), and
# all that tell where a thing is ("the towel from the floor").
_NEAR = ("in front of", "next to", "close to", "by", "beside", "near", "behind", "under", "at")
_WHERE = tuple(tuple(w.split()) for w in (*_NEAR, "on top of", "underneath", "on", "from", "in", "inside", "off"))
# Words that start a clause telling more of a thing before where it is ("the charger that's plugged in by
# the desk").
_RELATIVE = frozenset({"that", "which", "who"})
# A thing's name ends where a clause tells where it is ("the remote is on the coffee table", "my keys are
# right by the door", "the mug's on the desk").
_TELLING_WHERE = _RELATIVE | {"is", "are", "s", "was", "were"}
_PLACE_OPENERS = _OWNER | set(DETERMINERS)
# A point's way followed by "of" says what the point lies from; only the start or the robot itself is read
# ("1 m left of the start", "2 m in front of where you started"), not "1 m left of the table".
_OF_START = re.compile(r" of (?:the start|your start|the starting|where you|you\b|yourself\b|it\b|here\b)")
# A coordinate named ("x 2, y -1"): the point is said by its coordinates, not from the start.
_COORDINATE_NAMED = re.compile(r"\b[xy]\b")
# A noun said as the robot's own: "your gripper", "its camera"; and one said as where a thing is.
_OWN_PART = re.compile(r"\b(?:your|its|the robot's) (?:own )?([a-z]+)")
_PART_AS_PLACE = re.compile(rf"\b(?:{'|'.join((*_NEAR, 'below', 'above'))}) "
                            r"(?:your|its|the robot's) (?:own )?(?:left |right )?([a-z]+)")
_TOLERANCE = 0.02


@dataclass(frozen=True)
class Doubt:
    """One disagreement between the task and the plan; `reason` is said to the person."""

    check: str
    reason: str
    # The plan's steps (from 0) it is about, where the check can tell which and leaving them out may mend it.
    steps: tuple[int, ...] = ()


def check_meaning(task: str, plan: Plan, profile: Profile, known_objects: Collection[str] | None = None
                  ) -> tuple[Doubt, ...]:
    """Every disagreement between the normalized `task` and `plan`; empty when they agree."""
    vocab = vocabulary(profile)
    text, took_a_way = _as_read(task, vocab)
    taken_ways = {WHOLE} if took_a_way else set()
    # A bare "no" before a correction ("left, no, make that right") takes a word back, not the clause.
    negated = " ".join(m.group(0) for m in _NEGATION.finditer(text) if m.group(0).strip() not in MARKERS)
    affirmed = _NEGATION.sub(lambda m: m.group(0) if m.group(0).strip() in MARKERS else " ", text)
    words = _words(affirmed, vocab)
    # The conventions named anywhere bound and allow; only those named outside a negation must be done.
    named = _named(WORD.findall(text), vocab)
    doubts: list[Doubt] = []
    doubts += _parts(plan, vocab, words, set(WORD.findall(negated)), named, profile,
                     _asked_by_unlisted_verbs(affirmed, vocab) | _points_asked(affirmed, plan, vocab) | taken_ways
                     | ({WHOLE} if _SELF.search(affirmed) else set()),
                     _asked_by_command_verbs(affirmed, vocab))
    doubts += _directions(plan, vocab, words, named, profile)
    doubts += _numbers(text, plan, vocab, profile)
    doubts += _totals(text, plan, vocab, named)
    doubts += _repeated_after(text, plan, profile)
    doubts += _again(text, plan, profile)
    doubts += _repetitions(text, plan, profile)
    doubts += _restated(text, plan, vocab, profile)
    doubts += _doubled(text, plan, profile)
    doubts += _ways_gone(affirmed, plan, vocab)
    doubts += _way_unsaid(affirmed, plan, vocab, profile)
    doubts += _point_from_start(text, plan, vocab, named, profile)
    doubts += _cancelled(text, plan, vocab, profile)
    doubts += _only(affirmed, plan, vocab, named, profile)
    affirmed_named = _named(WORD.findall(affirmed), vocab)
    doubts += _carried_out(affirmed_named, text, plan, vocab)
    doubts += _one_object(named, plan)
    doubts += _negated_done([c for c in named if c not in affirmed_named], plan, vocab)
    doubts += _objects(text, affirmed, plan, known_objects, vocab)
    doubts += _corrected_objects(text, plan, profile)
    doubts += _places(text, plan, profile)
    doubts += _corrected_ways(text, plan, vocab, profile)
    doubts += _own_parts(text, plan, vocab, profile)
    if _FRAMED.search(text):
        doubts.append(Doubt("framed", f"you told of an order, imagined one or planned one for later, but did not "
                                      f"give it, and the plan acts ({say(plan.commands[0], profile)})"))
    done = _DONE_BY_SPEAKER.match(text)
    if _NARRATED.search(text) or (done is not None and done.group(1) in vocab.past_forms):
        doubts.append(Doubt("narrated", f"you told what you are doing or did, not what the robot should do, and "
                                        f"the plan acts ({say(plan.commands[0], profile)})"))
    if _QUESTION.match(text):
        doubts.append(Doubt("question", f"you asked a question, not for the robot to act, but the plan acts "
                                        f"({say(plan.commands[0], profile)})"))
    called_off = _called_off(text, vocab)
    if called_off:
        doubts.append(Doubt("called-off", f'you called it off ("{called_off}"), but the plan still acts '
                                          f"({say(plan.commands[0], profile)})"))
    reported = [m for m in _DONE_BY_SOMEONE.finditer(text) if m.group(1) in vocab.past_forms]
    if reported:
        told = reported[0].group(0).strip(", ")
        doubts.append(Doubt("reported", f'you told what was done ("{told}"), not what the robot should do, and '
                                        f"the plan acts ({say(plan.commands[0], profile)})"))
    doubts += _addressed(text, plan, vocab, profile)
    doubts += _not_reached(text, plan, vocab, profile)
    return tuple({d.reason: d for d in doubts}.values())


# What may come between a word of going and the step's word: "go over and pick up", "come back and grab".
_GOING_BETWEEN = frozenset({"over", "on", "and", "back", "there", "then"})


def _not_reached(text: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """A thing the task says to go and act on ("go pick up the mug") is gone to first.

    The skill the profile names to reach a thing out of reach (`out_of_reach`) is the going; a plan that
    picks the thing up where the robot stands does not do it."""
    tokens = WORD.findall(text)
    found = []
    for index, command in enumerate(plan):
        reaching = vocab.reached_by.get(command.skill)
        things = _things(command)
        if reaching is None or not things:
            continue
        if any(c.skill == reaching and _things(c) == things for c in plan.commands[:index]):
            continue
        words = vocab.step_words.get(command.skill, frozenset())
        for at, token in enumerate(tokens):
            if not any(_inflected(token, w) for w in words):
                continue
            before = at - 1
            while before >= 0 and at - before <= 3 and tokens[before] in _GOING_BETWEEN:
                before -= 1
            if before >= 0 and tokens[before] in vocab.going_words:
                said = " ".join(tokens[before:at + 1])
                found.append((f'you said "{said}", but the plan does not go to the {things[0].replace("_", " ")} '
                              f"first ({say(command, profile)})", index))
                break
    return _grouped("reach", found)


def _addressed(text: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """A task said to someone else by name ("Mia, look up, there's a balloon!") asks nothing of the robot.

    Only a word that names a person is read so: a word the profile or the closed classes know, or one the
    profile says the robot is called, opens a task to the robot ("robot, look up", "so, look up")."""
    found = _CALLED.search(text)
    if found is None:
        return []
    who = found.group(1) or found.group(2)
    if who in profile.called or who in vocab.known_words or not names_a_person(who):
        return []
    return [Doubt("addressed", f'you spoke to "{who}", not to the robot, but the plan acts '
                               f"({say(plan.commands[0], profile)})")]


def _called_off(text: str, vocab: Vocabulary) -> str:
    """The words that call off all that was said before, when nothing is asked after them; "" when none."""
    found = list(_CALLED_OFF.finditer(text))
    last = found[-1] if found else None
    if last is None or not text[:last.start()].strip(" ,"):
        return ""
    after = text[last.end():]
    asked = vocab.asking_words
    if re.search(r"\d", after) or any(w in asked or any(len(a) >= 4 and _inflected(w, a) for a in asked)
                                       for w in WORD.findall(after)):
        return ""
    return last.group(0)


def _as_read(task: str, vocab: Vocabulary) -> tuple[str, bool]:
    """The normalized `task` as the checks read it, and whether "take" carried a way of the base ("take a
    left", which asks for the base): lower-case, with a verb that only carries a way or a noun of looking
    left out, and an "-ing" form after "mind", "before" or "after" read as its verb."""
    lowered = task.lower()
    took_a_way = any(m.group(1) in vocab.base_ways for m in _TAKE_A_WAY.finditer(lowered))
    carried = _TAKE_A_WAY.sub(lambda m: "" if m.group(1) in vocab.base_ways else m.group(0), lowered)
    text = _ASKED_DOING.sub(lambda m: f"{m.group(1)} to {_stem(m.group(2), vocab)}", _LIGHT_VERB.sub("", carried))
    return text, took_a_way


def _words(text: str, vocab: Vocabulary) -> set[str]:
    """The task's words, with a pair that spells a skill word joined: "back up" is `backup`, "pick up" `pickup`.

    A part's noun that starts a clause is a verb there ("head over to the
    table"), since the noun would need "your" or "the" before it: it asks
    the robot as a whole to move, not the part. One said as where a thing
    is ("the cup in front of your camera") asks nothing of the part. Words of driving right
    after another part's verb say how that part moves ("look straight
    ahead"), not that the robot drives.
    """
    tokens = WORD.findall(text)
    verbs = Counter(m.group(1) for m in _CLAUSE_START.finditer(text) if m.group(1) in vocab.noun_parts)
    said = Counter(t for t, how in zip(tokens, _ways_of_parts(tokens, vocab), strict=True) if not how)
    said -= Counter(m.group(1) for m in _PART_AS_PLACE.finditer(text))
    return ({t for t in said if verbs[t] < said[t]} | ({WHOLE} if verbs else set())
            | {a + b for a, b in itertools.pairwise(tokens) if a + b in vocab.skill_words})


def _ways_of_parts(tokens: list[str], vocab: Vocabulary) -> list[bool]:
    """For each token, whether it is a word of the whole robot said of another part's motion."""
    whole = vocab.part_words.get(WHOLE, frozenset())
    how = [False] * len(tokens)
    for i in range(1, len(tokens)):
        before = tokens[i - 1]
        after_verb = how[i - 1] or any(before == w or (len(w) >= 4 and before.startswith(w)
                                                       and len(before) <= len(w) + 3) for w in vocab.part_verbs)
        how[i] = tokens[i] in whole and after_verb
    return how


def _asked_by_unlisted_verbs(text: str, vocab: Vocabulary) -> set[str]:
    """The parts asked for by a verb the profile does not list, told by the way and amount after it.

    "scoot back 1 m", "roll forward a little": a word that starts a clause
    and names nothing the profile knows, followed by a way only one part
    goes and an amount, asks for that part as its own words would.
    """
    found: set[str] = set()
    for m in _CLAUSE_START.finditer(text):
        verb = m.group(1)
        after = vocab.way_and_amount.match(text, m.end(1))
        if verb in vocab.known_words or len(verb) < 3 or after is None:
            continue
        parts = {vocab.parts.get(k, WHOLE) for k in vocab.way_skills.get(after.group(1), ())}
        if len(parts) == 1:
            found |= parts
    return found


def _asked_by_command_verbs(text: str, vocab: Vocabulary) -> set[str]:
    """The steps a whole command's own verb asks for, told by the way after it.

    "face left": the word that starts a whole command of the profile ("face
    behind", a turn of the base) and no skill's words, followed by a way,
    asks for the steps of that way on the parts the command moves (turning
    left), and for nothing else ("face right, toward the window" asks for
    no drive to the window).
    """
    found: set[str] = set()
    for m in _CLAUSE_START.finditer(text):
        parts = vocab.command_verbs.get(m.group(1))
        way = _NEXT_WORD.match(text, m.end(1)) if parts else None
        if parts and way:
            found |= {k for k in vocab.way_skills.get(way.group(1), ()) if vocab.parts.get(k, WHOLE) in parts}
    return found


def _points_asked(text: str, plan: Plan, vocab: Vocabulary) -> set[str]:
    """The parts of the steps that go to a point said whole, whatever verb carries it ("proceed to
    the point 4, 1", "I need you over at 3, -2"): a person names a point to have the robot go there."""
    said = [(float(x), float(y)) for x, y in _POINT.findall(text)]
    found: set[str] = set()
    for c in plan:
        values = [a.value for a in c.args if isinstance(a, Quantity)]
        if c.skill in vocab.coordinates and len(values) == 2 and any(
                _close(values[0], x) and _close(values[1], y) for x, y in said):
            found.add(vocab.parts.get(c.skill, WHOLE))
    return found


def _stem(stem: str, vocab: Vocabulary) -> str:
    """The verb of an "-ing" form with "ing" cut off: "back" (backing), "drive" (driv), "grab" (grabb).

    It is read after "to", as a verb starting a clause, so an unlisted verb
    ("scooting") asks as `_asked_by_unlisted_verbs` reads it.
    """
    undoubled = stem[:-1] if stem[-1] == stem[-2] else stem
    return next((w for w in (stem, undoubled, stem + "e") if w in vocab.known_words), undoubled)


def _said(words: Iterable[str], direction: frozenset[str]) -> bool:
    return any(w == d or (len(w) >= 4 and d.startswith(w)) or (len(d) >= 4 and w.startswith(d))
               for w in words for d in direction)


def _parts(plan: Plan, vocab: Vocabulary, words: set[str], negated: set[str], named: list[ConventionReading],
           profile: Profile, also_asked: set[str], steps_asked: set[str]) -> list[Doubt]:
    """The base moves only when asked for motion; a request about the head moves only the head."""
    used = {vocab.parts.get(c.skill, WHOLE) for c in plan}
    allowed = {skill for c in named for skill in c.skills} | steps_asked
    asked = {part for part, ws in vocab.part_words.items() if words & ws} | also_asked
    doubts = []
    for part in sorted(used):
        moving = [c for c in plan if vocab.parts.get(c.skill) == part and c.skill not in allowed]
        if not moving or part in asked:
            continue
        example = say(moving[0], profile)
        if negated & vocab.part_words.get(part, frozenset()):
            doubts.append(Doubt("negation", f"you said not to move the {part}, but the plan does ({example})"))
        elif asked:
            said = " or ".join(f"the {p}" for p in sorted(asked))
            doubts.append(Doubt("part", f"you asked about {said}, but the plan moves the {part} ({example})"))
        elif part == WHOLE:
            doubts.append(Doubt("motion", f"you did not ask the robot to move, but the plan does ({example})"))
    for part in sorted(asked - used - {WHOLE}):
        doubts.append(Doubt("part", f"you asked about the {part}, but the plan never uses it"))
    return doubts


def _directions(plan: Plan, vocab: Vocabulary, words: set[str], named: list[ConventionReading],
                profile: Profile) -> list[Doubt]:
    """The plan goes the way that was said, and goes both ways only when both were said.

    A convention the task names may go both ways ("look around" pans left,
    then right).
    """
    allowed = {skill for c in named for skill in c.skills}
    doubts = []
    for skill, mine, opposite, theirs in vocab.directions:
        for said_words, unsaid_words, wrong in ((mine, theirs, opposite), (theirs, mine, skill)):
            if _said(words, said_words) and not _said(words, unsaid_words):
                hit = next((c for c in plan if c.skill == wrong), None)
                if hit is not None:
                    doubts.append(Doubt("direction", f"you said {min(said_words)}, but the plan goes the "
                                                     f"other way ({say(hit, profile)})"))
        both = [c for c in plan if c.skill in (skill, opposite) and c.skill not in allowed]
        if {c.skill for c in both} == {skill, opposite} and not (_said(words, mine) and _said(words, theirs)):
            back = next(c for c in both if c.skill != both[0].skill)
            doubts.append(Doubt("direction", f"the plan goes both ways ({say(both[0], profile)}, then "
                                             f"{say(back, profile)}), but you did not say both "
                                             f"{min(mine, key=len)} and {min(theirs, key=len)}"))
    return doubts


def _said_numbers(text: str) -> list[tuple[float, str]]:
    """The amounts said, less counts ("3 times") and numbers taken back ("1 m, no, 2 m")."""
    dropped = {m.start(1) for m in _COUNT.finditer(text)} | {m.start(1) for m in _TAKEN_BACK_NUMBER.finditer(text)}
    return [(abs(float(m.group(1))), m.group(2) or "") for m in NUMBER_UNIT.finditer(text)
            if m.start(1) not in dropped]


def _repeats_said(text: str) -> int:
    """How many clauses at the end of `text` ask only for everything before them once more
    ("go forward 1 m, and again, and again": 2); 0 where such a clause comes before another step or
    nothing comes before it."""
    clauses = [c.split() for c in re.split(r"[,;]|\.(?!\d)", text) if c.strip()]
    repeats = 0
    while clauses and set(clauses[-1]) <= _REPEAT_WORDS and set(clauses[-1]) & _REPEAT_ASKS:
        clauses.pop()
        repeats += 1
    if not clauses or any(set(c) <= _REPEAT_WORDS and set(c) & _REPEAT_ASKS for c in clauses):
        return 0
    return repeats


def _counts(text: str) -> int:
    count = 1 + _repeats_said(text)
    for found in _COUNT.findall(text):
        count *= max(1, int(found))
    for sides in _sides_said(text):
        count *= sides
    return count


def _sides_said(text: str) -> list[int]:
    """The sides of each shape the task names ("walk a square": 4)."""
    return [sides for shape, sides in SHAPES.items() if re.search(rf"\b{shape}\b", text)]


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= max(_TOLERANCE, 0.01 * abs(b))


def _numbers(text: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """Every number said is in the plan; every number in the plan was said or is a convention's."""
    said = _said_numbers(text)
    planned = [(abs(a.value), a.unit, c) for c in plan for a in c.args if isinstance(a, Quantity)]
    amounts = [(v, u, c) for v, u, c in planned if c.skill not in vocab.coordinates]
    doubts = []
    for value, unit in said:
        if not any(_close(v, value) and (not unit or u == unit) for v, u, _c in planned):
            shown = quantity(Quantity(value, unit)) if unit else f"{value:g}"
            doubts.append(Doubt("number", f"you said {shown}, but the plan never uses it"))
    count = _counts(text)
    shape_turns = {2 * math.pi / n for n in SHAPES.values()}
    for value, unit, command in amounts:
        said_here = [v for v, u in said if not u or u == unit]
        if any(_close(value, v * k) for v in said_here for k in range(1, count + 1)):
            continue
        # More steps in this unit than amounts said (repetitions aside): some step was said without
        # one, and a convention's amount (the default) stands in for it.
        steps = sum(1 for _v, u, _c in amounts if u == unit)
        unsaid = steps > len(said_here) * count
        if (unsaid or not said_here) and any(_close(value, v) for v in vocab.convention_numbers.get(unit, ())):
            continue
        if unit == "rad" and any(_close(value, t) for t in shape_turns):
            continue
        doubts.append(Doubt("number", f"the plan uses {quantity(Quantity(value, unit))} "
                                      f"({say(command, profile)}), which you did not say"))
    return doubts


def _totals(text: str, plan: Plan, vocab: Vocabulary, named: list[ConventionReading]) -> list[Doubt]:
    """The whole turn and the whole drive of the base fit what was said."""
    count = _counts(text)
    said = _said_numbers(text)
    doubts = []
    for unit, noun, verb in (("rad", "turn", "turns"), ("m", "distance", "drives")):
        moves = [c for c in plan if vocab.parts.get(c.skill) == WHOLE and c.skill not in vocab.coordinates]
        planned = sum(abs(a.value) for c in moves for a in c.args if isinstance(a, Quantity) and a.unit == unit)
        if planned == 0:
            continue
        # A bare number ("go forward two") may be an amount in either unit.
        said_total = sum(v for v, u in said if u in (unit, ""))
        counted = said_total > 0 and _COUNT.search(text) is not None
        if said_total == 0:
            said_total = _vague_amount(named, vocab, unit)
        limit = said_total * count
        # Without a said count and amount a turn may fairly come out as up to a full circle
        # ("spin around"); with both, one repetition too many is what goes wrong.
        floor = 2 * math.pi if unit == "rad" and not counted else 0.0
        if counted:
            limit += _conventions_said(named, unit)
        if planned > max(limit, floor) * 1.01 + _TOLERANCE:
            doubts.append(Doubt("total", f"you said {quantity(Quantity(limit, unit))} of {noun} in all, "
                                         f"but the plan {verb} {quantity(Quantity(planned, unit))}"))
    return doubts


def _again(text: str, plan: Plan, profile: Profile) -> list[Doubt]:
    """What the task asks for once more at its end ("..., and repeat that once more") is done again: the
    plan repeats a step, or does an amount said that many times over in one."""
    repeats = _repeats_said(text)
    steps = [(c.skill, c.args) for c in plan]
    if not repeats or len(set(steps)) < len(steps):
        return []
    said = [v for v, _u in _said_numbers(text)]
    amounts = [abs(a.value) for c in plan for a in c.args if isinstance(a, Quantity)]
    if any(_close(a, v * (repeats + 1)) for a in amounts for v in said):
        return []
    done = ", then ".join(say(c, profile) for c in plan.commands)
    return [Doubt("again", f"you asked for it {repeats + 1} times in all, but the plan does it once ({done})",
                  tuple(range(len(steps))))]


def repeated(plan: Plan, task: str, profile: Profile) -> str:
    """The program of `plan` done as many times as the end of the normalized `task` asks ("..., and again":
    twice), read as the "again" check reads it."""
    return plan.to_rsl() * (1 + _repeats_said(_as_read(task, vocabulary(profile))[0]))


def _repeated_after(text: str, plan: Plan, profile: Profile) -> list[Doubt]:
    """A step said after the count is done once: "forward 1 m 3 times then turn right" repeats only the drive.

    Only the plainest miss is read: one count, a step after it, and a plan
    that is a block of several steps repeated exactly that many times.
    """
    counts = list(_COUNT.finditer(text))
    if len(counts) != 1 or not _STEP_AFTER.match(text, counts[0].end()):
        return []
    times = int(counts[0].group(1))
    steps = [(c.skill, c.args) for c in plan]
    size = len(steps) // times if times > 1 else 0
    if size < 2 or steps != steps[:size] * times:
        return []
    block = ", then ".join(say(c, profile) for c in plan.commands[:size])
    return [Doubt("repetition", f"you said to repeat something {times} times and then go on, but the plan "
                                f"repeats all of it ({block})")]


def _repetitions(text: str, plan: Plan, profile: Profile) -> list[Doubt]:
    """A plan that is one block said N times over is that block N times: "..., four times" is no five.

    Only a plan made wholly of one block repeated is read, against the one
    count said. A shape's sides may multiply the count ("a square, twice"
    is eight sides), and a word of doing again may add one ("3 times, then
    once more").
    """
    counts = [int(found) for found in _COUNT.findall(text)]
    if len(counts) != 1 or counts[0] < 2:
        return []
    steps = [(c.skill, c.args) for c in plan]
    size = next((s for s in range(1, len(steps) // 2 + 1)
                 if len(steps) % s == 0 and steps == steps[:s] * (len(steps) // s)), 0)
    if not size:
        return []
    said = counts[0]
    allowed = {said} | {said * sides for sides in _sides_said(text)}
    if _AGAIN.search(text):
        allowed.add(said + 1)
    times = len(steps) // size
    if times in allowed:
        return []
    block = ", then ".join(say(c, profile) for c in plan.commands[:size])
    return [Doubt("repetitions", f"you said {said} times, but the plan does {block} {times} times")]


def _restated(text: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """Two amounts said one after the other, both done by back-to-back steps.

    "turn right 90 degrees, correction, 45 degrees" most likely takes the
    first amount back; a word between that names a step, a part or a
    sequence ("then", "another") makes them two steps of one skill. After a
    marker that takes something back, the step said again ("back up 1 m,
    scratch that, back up half a metre") is the same step corrected, in
    whichever order and by whichever skills the plan does both.
    """
    doubts = []
    found = [(m, False) for m in _RESTATED.finditer(text)] + [(m, True) for m in _CORRECTED_AMOUNT.finditer(text)]
    for m, marked in found:
        between = set(WORD.findall(m.group(3)))
        if between & _SEQUENCE_WORDS or (not marked and between & (vocab.skill_words | vocab.noun_parts.keys())):
            continue
        first, second, unit = float(m.group(1)), float(m.group(4)), m.group(2)
        for a, b in itertools.pairwise(plan):
            if not marked and a.skill != b.skill:
                continue
            mine = [abs(x.value) for x in a.args if isinstance(x, Quantity) and x.unit == unit]
            theirs = [abs(y.value) for y in b.args if isinstance(y, Quantity) and y.unit == unit]
            if not any((_close(x, first) and _close(y, second)) or (marked and _close(x, second) and _close(y, first))
                       for x, y in itertools.product(mine, theirs)):
                continue
            said = f"{quantity(Quantity(first, unit))} and then {quantity(Quantity(second, unit))}"
            both = f"{say(a, profile)}, then {say(b, profile)}"
            doubts.append(Doubt("restated", f"you took back {quantity(Quantity(first, unit))} for "
                                            f"{quantity(Quantity(second, unit))}, but the plan does both ({both})"
                                if marked else f"you said {said}; if the second corrects the first, the plan "
                                               f"should not do both ({both})"))
            break
    return list({d.reason: d for d in doubts}.values())


def _doubled(text: str, plan: Plan, profile: Profile) -> list[Doubt]:
    """The same step twice in a row is asked for: by a count, a word of doing again, or its amount said twice."""
    if _counts(text) > 1 or _AGAIN.search(text):
        return []
    said = _said_numbers(text)
    for a, b in itertools.pairwise(plan):
        if a.skill != b.skill or a.args != b.args:
            continue
        amounts = [abs(x.value) for x in a.args if isinstance(x, Quantity)]
        if any(sum(1 for value, _unit in said if _close(value, amount)) >= 2 for amount in amounts):
            continue
        return [Doubt("doubled", f"the plan does the same step twice in a row ({say(a, profile)}), but you "
                                 "did not ask for it twice")]
    # Apart too: a step on a thing named once ("fetch the ball, then look around" going for the ball twice).
    words = Counter(WORD.findall(text))
    steps = [(c.skill, c.args) for c in plan]
    for at, command in enumerate(plan):
        names = [x.name for x in command.args if isinstance(x, ObjectRef)]
        if (names and steps[at] in steps[at + 1:]
                and all(words[w] <= 1 for name in names for w in name.lower().split("_"))):
            return [Doubt("doubled", f"the plan does the same step twice ({say(command, profile)}), but you "
                                     "named it once")]
    return []


def _ways_gone(affirmed: str, plan: Plan, vocab: Vocabulary) -> list[Doubt]:
    """Every way said of a part the plan moves is a way it goes: "go right 2 m" is no straight drive.

    Only plans whose moving steps all have a way are read: a drive to an
    object or a point ("come back", "go right to the door") goes whichever
    way it must.
    """
    ways = vocab.way_skills
    directed = {k for keywords in ways.values() for k in keywords}
    moving = [c.skill for c in plan if c.skill in directed or vocab.parts.get(c.skill) == WHOLE]
    if not moving or any(skill not in directed for skill in moving):
        return []
    moved = {vocab.parts.get(skill) for skill in moving}
    planned = {c.skill for c in plan}
    # "left, no, make that right" takes the first way back.
    taken_back = {m.start(1) for m in _TAKEN_BACK_WORD.finditer(affirmed) if m.group(2) in ways}
    tokens = ["", *(m.group(0) for m in WORD.finditer(affirmed) if m.start() not in taken_back), ""]
    doubts = []
    for before, token, after in zip(tokens, tokens[1:], tokens[2:], strict=False):
        # "pick up", "back up": the way is part of a word that names a step.
        joined = before + token in vocab.skill_words or token + after in vocab.skill_words
        if token not in ways or joined or after in _PLACE_OR_TIME or before in _OWNER:
            continue
        keywords = ways[token]
        if keywords & planned or not {vocab.parts.get(k) for k in keywords} & moved:
            continue
        doubts.append(Doubt("way", f"you said {token}, but the plan never goes {token}"))
    return list({d.reason: d for d in doubts}.values())


def _way_unsaid(affirmed: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """A step gone the other way than a convention goes when no way is said: "spin in a full circle" turns
    as its example does, and a plan that turns the other way by that amount was not asked for.

    Only a task that says no way, and no word naming only that step ("reverse" names a drive back), is read.
    """
    words = set(WORD.findall(affirmed))
    if words & vocab.way_skills.keys():
        return []
    unsaid = [u for u in vocab.unsaid_ways
              if not words & (vocab.step_words.get(u.against, frozenset()) - vocab.step_words.get(u.way, frozenset()))]
    doubts = []
    for i, step in enumerate(plan.commands):
        amounts = [a for a in step.args if isinstance(a, Quantity)]
        match = next((u for u in unsaid if step.skill == u.against and amounts
                      and any(_close(amounts[0].value, v) for v in u.amounts.get(amounts[0].unit, ()))), None)
        if match is not None:
            said_way = say(Command(match.way, step.args, step.line, step.column), profile)
            doubts.append(Doubt("unsaid way", f'you did not say which way, so it goes as "{match.task}" does '
                                              f"({said_way}), but the plan goes the other way "
                                              f"({say(step, profile)})", (i,)))
    return doubts


def said_point(task: str, profile: Profile) -> dict[str, float] | None:
    """The point the normalized `task` says by amounts and ways from the start, read as the "point" check
    reads it."""
    vocab = vocabulary(profile)
    return _point_said(_as_read(task, vocab)[0], vocab)


def _point_said(text: str, vocab: Vocabulary) -> dict[str, float] | None:
    """The point `text`, as the checks read it, says by amounts and ways from the start ("the spot 2 m
    ahead and 1 m to your right": x 2, y -1), by axis; None when it says none, says an axis twice, or gives
    the point whole or by its coordinates.
    """
    if _POINT.search(text) or _COORDINATE_NAMED.search(text):
        return None
    point: dict[str, float] = {}
    for m in vocab.point_offset.finditer(text):
        if text.startswith(" of ", m.end()) and not _OF_START.match(text, m.end()):
            return None
        axis, sign = vocab.frame[m.group(2)]
        if axis in point:
            return None
        point[axis] = sign * float(m.group(1))
    return point or None


def at_point(step: Command, point: dict[str, float], profile: Profile) -> Command | None:
    """`step`, a drive to a point, driving to `point` instead (an axis not in it is 0)."""
    skill = profile.skill(step.skill)
    if skill is None or len(skill.params) != len(step.args) or not all(p.axis for p in skill.params):
        return None
    return Command(step.skill, tuple(Quantity(point.get(str(p.axis), 0.0), p.unit) for p in skill.params),
                   step.line, step.column)


def _point_from_start(text: str, plan: Plan, vocab: Vocabulary, named: list[ConventionReading],
                      profile: Profile) -> list[Doubt]:
    """A drive to a point said from the start goes to that point, and the point's amounts are not driven
    again after it as steps of their own ("2 m ahead and 1 m to your right" is one drive to (2, -1)).

    Only a plan with one drive to a point, and no other move of the base before it, is read: from
    anywhere else the start's ways are not the robot's. A convention that drives to a point of its own
    ("back to the start") leaves the task unread.
    """
    point = _point_said(text, vocab)
    if point is None or any(vocab.coordinates & c.skills for c in named):
        return []
    gotos = [i for i, c in enumerate(plan) if c.skill in vocab.coordinates]
    if len(gotos) != 1:
        return []
    at = gotos[0]
    said = {abs(v) for v in point.values()}
    spent = []
    for i, c in enumerate(plan.commands):
        if i == at or vocab.parts.get(c.skill) != WHOLE:
            continue
        if i < at:
            return []
        if any(a.unit == "m" and any(_close(abs(a.value), v) for v in said) for a in c.args
               if isinstance(a, Quantity)):
            spent.append(i)
    goto = plan.commands[at]
    meant = at_point(goto, point, profile)
    there = meant is not None and all(_close(a.value, b.value) for a, b in zip(goto.args, meant.args, strict=True)
                                      if isinstance(a, Quantity) and isinstance(b, Quantity))
    if meant is None or (there and not spent):
        return []
    ways = " and ".join(m.group(0) for m in vocab.point_offset.finditer(text))
    said_where = f"you said the point {ways} from the start, {_where(meant)}"
    also = f"{say(plan.commands[spent[0]], profile)} as well" if spent else ""
    if there:
        reason = f"{said_where}, and the plan drives there but does {also}"
    else:
        reason = f"{said_where}, but the plan drives to {_where(goto)}" + (f" and does {also}" if also else "")
    return [Doubt("point", reason, (at, *spent))]


def _where(step: Command) -> str:
    """A drive to a point's coordinates as people read them: "(2 m, -1 m)"."""
    return "(" + ", ".join(quantity(a) for a in step.args if isinstance(a, Quantity)) + ")"


def _grouped(check: str, found: Iterable[tuple[str, int]]) -> list[Doubt]:
    """One doubt of `check` for each reason found, naming every step (from 0) found with it."""
    steps: dict[str, list[int]] = {}
    for reason, index in found:
        steps.setdefault(reason, []).append(index)
    return [Doubt(check, reason, tuple(indices)) for reason, indices in steps.items()]


def _things(command: Command) -> list[str]:
    """The names of the objects `command` acts on, in lower case."""
    return [a.name.lower() for a in command.args if isinstance(a, ObjectRef)]


def _cancelled(text: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """A step whose last mention takes it back ("..., actually skip the turn") is not in the plan."""
    spans = [(m.start(), m.end(), m.group(0).strip()) for m in _CANCELLED.finditer(text)]
    if not spans:
        return []
    mentions = [(m.start(), m.group(0)) for m in WORD.finditer(text)]
    found = []
    for index, command in enumerate(plan):
        words = vocab.step_words.get(command.skill, frozenset())
        last = next((at for at, token in reversed(mentions) if any(_inflected(token, w) for w in words)), None)
        span = next((said for start, end, said in spans if last is not None and start <= last < end), None)
        if span is not None:
            found.append((f'you said "{span}", but the plan still does it ({say(command, profile)})', index))
    return _grouped("cancelled", found)


def _only(affirmed: str, plan: Plan, vocab: Vocabulary, named: list[ConventionReading], profile: Profile
          ) -> list[Doubt]:
    """A part said with "only" ("turn left, but only your head") is the only part that moves."""
    kept = {vocab.noun_parts[m.group(1)] for pattern in _ONLY for m in pattern.finditer(affirmed)
            if m.group(1) in vocab.noun_parts}
    if not kept:
        return []
    # A whole command named ("look around") may move what it moves; an amount's convention excuses nothing.
    allowed = {skill for c in named if c.whole for skill in c.skills}
    moving = [c for c in plan if vocab.parts.get(c.skill, WHOLE) not in kept and c.skill not in allowed]
    if not moving:
        return []
    said = " or ".join(f"the {p}" for p in sorted(kept))
    return [Doubt("only", f"you asked to move only {said}, but the plan moves the "
                          f"{vocab.parts.get(moving[0].skill, WHOLE)} ({say(moving[0], profile)})")]


def _inflected(token: str, word: str) -> bool:
    """Whether `token` is `word` or one of its inflections ("turning", "grabbed")."""
    return token == word or (token.startswith(word.rstrip("e")) and len(token) <= len(word) + 3)


def _one_object(named: list[ConventionReading], plan: Plan) -> list[Doubt]:
    """Where a named convention acts on one thing in consecutive steps ("fetch"), the plan does too."""
    pairs = {pair for c in named for pair in c.same_object}
    doubts = []
    for a, b in itertools.pairwise(plan):
        first = [x.name for x in a.args if isinstance(x, ObjectRef)]
        second = [x.name for x in b.args if isinstance(x, ObjectRef)]
        if (a.skill, b.skill) in pairs and first and second and first != second:
            doubts.append(Doubt("same-object", f"the plan goes for the {first[0].replace('_', ' ')} but then takes "
                                               f"the {second[0].replace('_', ' ')}"))
    return doubts


def _negated_done(negated: list[ConventionReading], plan: Plan, vocab: Vocabulary) -> list[Doubt]:
    """A convention said only to deny it ("no need to look around") is not carried out."""
    planned = _amounts(plan, vocab)
    skills = {c.skill for c in plan}
    doubts = []
    for convention in negated:
        if convention.default:
            continue
        amount = any(_close(value, amount) for unit, amounts in convention.amounts.items() for amount in amounts
                     for value, planned_unit in planned if planned_unit == unit)
        if (convention.skills <= skills or not convention.whole) and (amount or not convention.amounts):
            doubts.append(Doubt("negated-convention", f'you said not "{convention.phrase}" '
                                                      f"({convention.meaning}), but the plan does it"))
    return doubts


# How many words may stand between a phrase's own ("turn all the way around" names "turn around").
_PHRASE_GAP = 3


def _names(tokens: list[str], convention: ConventionReading, vocab: Vocabulary) -> bool:
    """Whether the task's words name `convention`: its words in order, a few others between.

    A word between that asks for a step of its own breaks the phrase: "turn
    left and go around the table" names no turning around. A long word
    names its inflections ("exploring", "the starting point").
    """
    first, *rest = convention.words
    for start, token in enumerate(tokens):
        if not _same(token, first):
            continue
        at = start
        for word in rest:
            found = next((i for i in range(at + 1, min(len(tokens), at + 2 + _PHRASE_GAP))
                          if _same(tokens[i], word) or tokens[i] in vocab.skill_words), None)
            if found is None or not _same(tokens[found], word):
                break
            at = found
        else:
            return True
    return False


def _same(token: str, word: str) -> bool:
    return token == word or (len(word) >= 5 and token.startswith(word.rstrip("e")))


def _named(tokens: list[str], vocab: Vocabulary) -> list[ConventionReading]:
    """The conventions these words name."""
    return [c for c in vocab.conventions if _names(tokens, c, vocab)]


def _carried_out(named: list[ConventionReading], text: str, plan: Plan, vocab: Vocabulary) -> list[Doubt]:
    """A convention the task names is done: a whole command's skills (or their opposites), and its amount.

    The amount is looked for only in units the task gives no number in, and
    any one of the convention's units will do: "a little" is 20 cm of a drive
    or 15° of a turn, whichever step it was said of.
    """
    said_units = {u for _v, u in _said_numbers(text)}
    count = _counts(text)
    skills = {c.skill for c in plan}
    planned = _amounts(plan, vocab)
    doubts = []
    for convention in named:
        if convention.default:
            continue
        missing = convention.whole and any(s not in skills and vocab.opposites.get(s) not in skills
                                           for s in convention.skills)
        units = [u for u in convention.amounts if u not in said_units and "" not in said_units]
        done = not units or any(_close(value, amount * k) for unit in units for amount in convention.amounts[unit]
                                for value, planned_unit in planned if planned_unit == unit
                                for k in range(1, count + 1))
        if missing or not done:
            doubts.append(Doubt("convention", f'you said "{convention.phrase}" ({convention.meaning}), '
                                              "but the plan does not do that"))
    return doubts


def _amounts(plan: Plan, vocab: Vocabulary) -> list[tuple[float, str]]:
    """The amounts the plan's steps take, without sign, less positions."""
    return [(abs(a.value), a.unit) for c in plan if c.skill not in vocab.coordinates
            for a in c.args if isinstance(a, Quantity)]


def _conventions_said(named: list[ConventionReading], unit: str) -> float:
    """What the conventions named in the task add ("then turn around": 180°)."""
    return sum(max(c.amounts.get(unit, (0.0,))) for c in named)


def _vague_amount(named: list[ConventionReading], vocab: Vocabulary, unit: str) -> float:
    """The most a task that says no number may mean: its conventions' amounts, else the defaults'."""
    used = [c.amounts for c in named] or [c.amounts for c in vocab.conventions if c.default]
    return max((v for values in used for v in values.get(unit, ())), default=0.0)


def _in_a_row(parts: list[str], text: str) -> bool:
    """Whether `parts` are said one after another, with no clause break between them."""
    for piece in re.split(r"[,;]|\.(?!\d)", text):
        tokens = WORD.findall(piece)
        if any(tokens[i:i + len(parts)] == parts for i in range(len(tokens))):
            return True
    return False


# Words that say a thing again without its name.
_REFERS_BACK = re.compile(r"\b(?:it|them|there)\b")
# A negation word that also starts a self-correction ("no, the keys") corrects rather than denies.
_CORRECTING = frozenset(m.split()[0] for m in MARKERS)


def _objects(text: str, affirmed_text: str, plan: Plan, known: Collection[str] | None, vocab: Vocabulary
             ) -> list[Doubt]:
    """Every object in the plan was said, and every known object said is in the plan."""
    known_words = {w for name in known or () for w in name.lower().split("_")}
    taken_back = {m.group(1) for m in _TAKEN_BACK_WORD.finditer(text) if m.group(2) in known_words}
    words = set(WORD.findall(text))
    # "not the chair" denies an object; "no, the keys" corrects to one. "don't grab the mug, just go to it"
    # denies a step the plan leaves out, and the rest says the thing again.
    denied: set[str] = set()
    planned_skills = {c.skill for c in plan}
    said_again = _REFERS_BACK.search(affirmed_text) is not None

    def deny(m: re.Match[str]) -> str:
        said = WORD.findall(m.group(0))
        steps = {skill for skill, step_words in vocab.step_words.items()
                 if any(_inflected(token, w) for token in said for w in step_words)}
        if said[0] in _CORRECTING or (said_again and steps and not steps & planned_skills):
            return m.group(0)
        denied.update(said)
        return " "

    affirmed = set(WORD.findall(_NEGATION.sub(deny, text)))
    planned = {a.name for c in plan for a in c.args if isinstance(a, ObjectRef)}
    doubts = []
    for name in sorted(planned):
        name_words = set(name.lower().split("_"))
        if name.lower() in vocab.skill_words:
            doubts.append(Doubt("object", f"the plan takes '{name}' for an object, but it names a direction "
                                          "or an action"))
        elif name.lower() in DETERMINERS:
            doubts.append(Doubt("object", f"the plan takes '{name}' for an object, but it is a word that comes "
                                          "before a thing's name"))
        elif not (name_words & words):
            doubts.append(Doubt("object", f"the plan uses the {name.replace('_', ' ')}, which you did not mention"))
        elif (acting := sorted(name_words & vocab.skill_words)) and not _in_a_row(name.lower().split("_"), text):
            doubts.append(Doubt("object", f"the plan takes '{name}' for one thing's name, but you did not say "
                                          f"it so, and '{acting[0]}' names a direction or an action"))
        elif not name_words <= affirmed and name_words <= denied:
            doubts.append(Doubt("negation", f"you said not the {name.replace('_', ' ')}, but the plan uses it"))
    tokens = WORD.findall(text)
    for name in sorted(known or ()) if planned else ():
        parts = name.lower().split("_")
        # A thing said only as where another is ("the cup on the table") need not be acted on.
        if (all(p in affirmed for p in parts) and not set(parts) & taken_back and _thing_at(tokens, parts) is None
                and not any(set(parts) <= set(p.split("_")) for p in planned)):
            doubts.append(Doubt("object", f"you mentioned the {name.replace('_', ' ')}, but the plan never uses it"))
    return doubts


def _corrected_objects(text: str, plan: Plan, profile: Profile) -> list[Doubt]:
    """A thing a self-correction takes back for another ("the knife, wait, no, the ladle") is not in the
    plan, unless it is said whole again after the correction. The plan must use the other thing too: a
    marker word may start other talk ("the cup, no hurry"), and a word of sequence after it adds a thing
    ("the cup, sorry, and the plate")."""
    names = [(index, name.split("_")) for index, c in enumerate(plan) for name in _things(c)]
    found = []
    for correction in _CORRECTION.finditer(text):
        before = WORD.findall(text[:correction.start()])
        rest = WORD.findall(text[correction.end():])
        if not rest or rest[0] in _SEQUENCE_WORDS:
            continue
        after = set(rest)
        corrected_to = {"_".join(parts) for _, parts in names if set(parts) <= after}
        for index, parts in names:
            if before[-len(parts):] == parts and not set(parts) <= after and corrected_to - {"_".join(parts)}:
                found.append((f"you took back the {' '.join(parts)}, but the plan still uses it "
                              f"({say(plan.commands[index], profile)})", index))
    return _grouped("corrected", found)


def _own_parts(text: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """A part of the robot said as its own ("the pen by your gripper") is where a thing is, never a thing
    to fetch or drive up to."""
    owned = {m.group(1) for m in _OWN_PART.finditer(text) if m.group(1) in vocab.noun_parts}
    return _grouped("own-part", ((f"your {name} is part of the robot, not a thing to act on, but the plan does "
                                  f"({say(command, profile)})", index)
                                 for index, command in enumerate(plan) for name in _things(command) if name in owned))


def things_at_places(task: str, plan: Plan) -> dict[int, str]:
    """The plan's steps (from 0) that act on a place the task only said as where a thing is ("the keys by
    the front door" -> `approach door;`), each with the thing's name."""
    tokens = WORD.findall(task)
    found: dict[int, str] = {}
    for index, command in enumerate(plan):
        for name in _things(command):
            thing = _thing_at(tokens, name.split("_"))
            if thing is not None and thing != name:
                found[index] = thing
    return found


def at_things(plan: Plan, task: str) -> str:
    """The program of `plan` with each step on a place said only as where a thing is acting on the thing
    instead; such a step after one on the thing already reached it, and one the plan also takes on the
    thing is there already, so either is left out."""
    found = things_at_places(task, plan)
    kept = [(c.skill, tuple(_things(c))) for i, c in enumerate(plan) if i not in found]
    commands = []
    for index, command in enumerate(plan):
        thing = found.get(index)
        if thing is None:
            commands.append(command)
            continue
        if (command.skill, (thing,)) in kept or any(thing in _things(c) for c in plan.commands[:index]):
            continue
        args = tuple(ObjectRef(thing) if isinstance(a, ObjectRef) else a for a in command.args)
        commands.append(Command(command.skill, args, command.line, command.column))
    return Plan(tuple(commands), plan.profile).to_rsl()


def _thing_at(tokens: list[str], place: list[str]) -> str | None:
    """The thing said right before `place` each time `place` is said as where it is; None when `place` is
    once said otherwise, or no plain name comes before it."""
    starts = [i for i in range(len(tokens)) if tokens[i:i + len(place)] == place]
    things = set()
    for start in starts:
        # The place may be the end of a longer name ("the front door" for `door`).
        at = next((i for i in range(start, max(-1, start - 3), -1) if i > 0 and tokens[i - 1] in _PLACE_OPENERS),
                  None)
        where = None if at is None else next((w for w in _WHERE if tokens[max(0, at - 1 - len(w)):at - 1] == list(w)),
                                             None)
        if at is None or where is None:
            return None
        before = tokens[max(0, at - 1 - len(where) - 6):at - 1 - len(where)]
        opened = max((i for i, t in enumerate(before) if t in DETERMINERS and t not in _RELATIVE), default=None)
        if opened is None:
            return None
        span = before[opened + 1:]
        span = span[:next((i for i, t in enumerate(span) if t in _TELLING_WHERE), len(span))]
        if not 0 < len(span) <= 2 or any(w in FUNCTION_WORDS or w in NOT_NAMES or w.endswith(("ing", "ly"))
                                         for w in span):
            return None
        things.add("_".join(span))
    return things.pop() if len(things) == 1 else None


def _places(text: str, plan: Plan, profile: Profile) -> list[Doubt]:
    """A place said only as where a thing is ("the keys by the front door") is not what the plan acts on."""
    found = []
    for index, thing in things_at_places(text, plan).items():
        command = plan.commands[index]
        place = next(a.name for a in command.args if isinstance(a, ObjectRef)).replace("_", " ")
        found.append((f"the {place} only tells where to find the {thing.replace('_', ' ')}, but the plan acts "
                      f"on it ({say(command, profile)})", index))
    return _grouped("place", found)


def _corrected_ways(text: str, plan: Plan, vocab: Vocabulary, profile: Profile) -> list[Doubt]:
    """A way taken back for its opposite ("turn left, hang on, right"; "pan left, scratch that, pan it
    right") is not gone, unless it is said again after the correction."""
    found = []
    for m in _WAY_CORRECTION.finditer(text):
        before, after = WORD.findall(text[:m.start()]), WORD.findall(text[m.end():])
        said = before[-1] if before else ""
        meant = next((w for w in after[:3] if w in vocab.way_skills or w in _SEQUENCE_WORDS), None)
        if said not in vocab.way_skills or meant not in vocab.way_skills or said in after:
            continue
        at = after.index(meant)
        if at + 1 < len(after) and after[at + 1] in _PLACE_OR_TIME:
            continue
        gone = {k for k in vocab.way_skills[said] if vocab.opposites.get(k) in vocab.way_skills[meant]}
        found += [(f"you took back \"{said}\" for \"{meant}\", but the plan still goes {said} "
                   f"({say(command, profile)})", index) for index, command in enumerate(plan) if command.skill in gone]
    return _grouped("corrected-way", found)
