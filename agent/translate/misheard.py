"""Words a recognizer writes for a direction or a colour, or splits in two, read back before a task is read.

A recognizer hears "right" as "write" or "rite". The model reads "turn
write" as a right turn, but unsurely, and "turn around to the write" as a
left one. Where the verb cannot be meant (after an article, before an
amount, at the end of a clause), the word is read as "right". It hears
"red" as "read" and "blue" as "blew": between a determiner and the thing's
noun ("the read ball") only the colour can be meant.

This runs at run time only, after `normalize_task`, and not on the
adapter's training data, so a retrain is not needed for it: the data keeps
its "write" for "right", and the model still learns to read the ones this
leaves ("write" after "you", where it may be the verb).

A recognizer also writes a word of the robot's in two ("drive for ward",
"a lit tle"): two words are joined where together they are a word of the
profile's skills or conventions and the second alone is none of its words.

It writes numbers as other words too. The normalizer reads "for" as four
before a unit and in a point said with a comma; a point said without one
("the point for too", "x for y too", "position for 3", "3 and for") is read
back here, and so are tens and hundreds heard as a homophone and a syllable
("for tee five degrees", "won hundred twenty"), before the normalizer reads
the number.
"""

from __future__ import annotations

import re

from agent.normalize import NUMBER_HOMOPHONES, ONES, normalize_task
from agent.translate.other_words import in_convention_words
from agent.translate.vocabulary import Vocabulary, vocabulary
from rsl.profile import Profile

_HEARD_FOR_RIGHT = frozenset({"write", "rite"})
# What cannot come right before the verb "write": an article, a possessive, or a word for how sharply to turn.
_BEFORE_NO_VERB = frozenset({"the", "a", "an", "your", "my", "hard", "sharp"})
# What may come right before the verb "write" ("you write", "please write"): then it is left alone. The
# normalizer has already dropped a leading "can you", so a first word is read back only before an amount.
_BEFORE_VERB = frozenset({"", "i", "you", "we", "they", "he", "she", "it", "can", "could", "will", "would",
                          "should", "must", "to", "please", "and", "then"})
# What cannot follow the verb "write": the end of a clause, or what a way is said of ("write side", "write turn").
_CLAUSE_WORDS = frozenset({"", ",", "and", "then", "please", "now", "again", "instead", "side", "turn"})
_HEARD_FOR_COLOUR = {"read": "red", "blew": "blue"}
_DETERMINERS = frozenset({"the", "a", "an", "your", "my", "that", "this"})


# Tens heard as a word and "tee" before a number's ones or "degrees" ("for tee five", "fif tee degrees"; not
# "look for tee shirts"), and a hundred's count heard as a homophone ("won hundred").
_TENS = {"for": "forty", "fore": "forty", "fif": "fifty", "six": "sixty", "seven": "seventy", "ate": "eighty",
         "nine": "ninety", "thir": "thirty", "twen": "twenty"}
_TENS_HEARD = re.compile(rf"\b({'|'.join(_TENS)}) tee (?=("
                         + "|".join(w for w, v in ONES.items() if 0 < v < 10) + "|" + "|".join(NUMBER_HOMOPHONES)
                         + r"|degrees?)\b)")
_TENS_UNITS = r"(?:degrees?|centimet(?:er|re)s?|cm)"
# "to hundred" is left out: "turn to hundred degrees" may be "to" and a number.
_HUNDREDS_HEARD = re.compile(rf"\b({'|'.join(h for h in NUMBER_HOMOPHONES if h != 'to')}) (hundred|thousand)\b")
_COUNTS = {heard: next(word for word, value in ONES.items() if value == number)
           for heard, number in NUMBER_HOMOPHONES.items()}
# Words that name a point right before its two coordinates ("the point for too"); "x" names the first of
# "x for y too".
_POINT_WORDS = frozenset({"point", "position", "coordinates", "coordinate", "location", "spot"})
_BETWEEN_COORDINATES = frozenset({",", "and", "comma"})


def heard(task: str, profile: Profile) -> str:
    """The task as the model and the checks read it: normalized, with mishearings read back and a
    convention's other words read as its phrase."""
    said = _TENS_HEARD.sub(lambda m: _TENS[m.group(1)] + " ", task.lower())
    # The ones after tens may be a homophone too ("for tee for degrees"); only before the units tens are
    # said in, so "twenty to the door" keeps its "to".
    said = re.sub(rf"\b({'|'.join(_TENS.values())}) ({'|'.join(NUMBER_HOMOPHONES)})(?= {_TENS_UNITS}\b)",
                  lambda m: f"{m.group(1)} {_COUNTS[m.group(2)]}", said)
    said = _HUNDREDS_HEARD.sub(lambda m: f"{_COUNTS[m.group(1)]} {m.group(2)}", said)
    # The normalizer writes a clause comma right after its word ("turn write, then").
    vocab = vocabulary(profile)
    words = _points(_joined(normalize_task(said).replace(",", " ,").split(), vocab))
    out = []
    for i, word in enumerate(words):
        before, after = words[i - 1] if i else "", words[i + 1:i + 4]
        if word in _HEARD_FOR_RIGHT and _not_the_verb(before, after, vocab.word_amounts):
            word = "right"
        elif (word in _HEARD_FOR_COLOUR and before in _DETERMINERS and after and after[0].isalpha()
              and after[0] not in _CLAUSE_WORDS):
            word = _HEARD_FOR_COLOUR[word]
        out.append(word)
    return in_convention_words(" ".join(out).replace(" ,", ","), profile)


def _joined(words: list[str], vocab: Vocabulary) -> list[str]:
    # A second half the profile knows ("turn left", "a head") or a number keeps the two words apart.
    robot_words = vocab.skill_words | {w for c in vocab.conventions for w in c.words}
    out: list[str] = []
    for word in words:
        if out and out[-1] + word in robot_words and word not in vocab.known_words and not _is_number(word):
            out[-1] += word
        else:
            out.append(word)
    return out


def _not_the_verb(before: str, after: list[str], amounts: frozenset[tuple[str, ...]]) -> bool:
    # Before an amount said in words ("write a little", "write a tad") only the way can be meant.
    if before in _BEFORE_NO_VERB:
        return True
    amount = bool(after) and (_is_number(after[0]) or any(tuple(after[:len(w)]) == w for w in amounts))
    if before in _BEFORE_VERB:
        return amount and not before
    return amount or (after[0] if after else "") in _CLAUSE_WORDS


def _is_number(word: str) -> bool:
    return word.replace(".", "", 1).isdigit()


def _points(words: list[str]) -> list[str]:
    """`words` with a point's coordinates heard as homophones read as numbers: "point for too" is "point 4,
    2", "x for y too" is "x 4 y 2". Both coordinates must be numbers or homophones, one a homophone."""
    out = list(words)
    for i, word in enumerate(words):
        pair = words[i + 1:i + 4]
        if word == "x" and len(pair) == 3 and pair[1] == "y":
            second = 2
        elif word in _POINT_WORDS and len(pair) >= 2:
            second = 2 if len(pair) == 3 and pair[1] in _BETWEEN_COORDINATES else 1
        else:
            continue
        said = (pair[0], pair[second])
        if not (all(_coordinate(w) for w in said) and set(said) & NUMBER_HOMOPHONES.keys()):
            continue
        out[i + 1], out[i + 1 + second] = (_digit(w) for w in said)
        if word != "x":
            # Said whole, a point is two numbers joined by a comma, as the normalizer writes "3 comma 2".
            out[i + 1] += ","
            if second == 2:
                out[i + 2] = ""
    return [w for part in out for w in part.replace(",", " ,").split()]


def _coordinate(word: str) -> bool:
    return word in NUMBER_HOMOPHONES or _is_number(word.removeprefix("-"))


def _digit(word: str) -> str:
    return str(NUMBER_HOMOPHONES[word]) if word in NUMBER_HOMOPHONES else word
