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
"""

from __future__ import annotations

from agent.normalize import normalize_task
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
# Amounts said in words that the normalizer leaves as words ("turn write a little").
_WORD_AMOUNTS = (("a", "little"), ("a", "bit"), ("slightly",))
_HEARD_FOR_COLOUR = {"read": "red", "blew": "blue"}
_DETERMINERS = frozenset({"the", "a", "an", "your", "my", "that", "this"})


def heard(task: str, profile: Profile) -> str:
    """The task as the model and the checks read it: normalized, with mishearings read back."""
    # The normalizer writes a clause comma right after its word ("turn write, then").
    words = _joined(normalize_task(task).replace(",", " ,").split(), vocabulary(profile))
    out = []
    for i, word in enumerate(words):
        before, after = words[i - 1] if i else "", words[i + 1:i + 3]
        if word in _HEARD_FOR_RIGHT and _not_the_verb(before, after):
            word = "right"
        elif (word in _HEARD_FOR_COLOUR and before in _DETERMINERS and after and after[0].isalpha()
              and after[0] not in _CLAUSE_WORDS):
            word = _HEARD_FOR_COLOUR[word]
        out.append(word)
    return " ".join(out).replace(" ,", ",")


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


def _not_the_verb(before: str, after: list[str]) -> bool:
    if before in _BEFORE_NO_VERB:
        return True
    amount = bool(after) and (_is_number(after[0]) or any(tuple(after[:len(w)]) == w for w in _WORD_AMOUNTS))
    if before in _BEFORE_VERB:
        return amount and not before
    return amount or (after[0] if after else "") in _CLAUSE_WORDS


def _is_number(word: str) -> bool:
    return word.replace(".", "", 1).isdigit()
