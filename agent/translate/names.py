"""The names a person gives things: "the red cup" names `red_cup`, not `cup`.

An object in RSL is one identifier, and a person often names a thing in
two words: a kind of thing ("the water bottle", "the toy box") or a thing
told apart from others ("the red cup"). The translator offers such a pair
to the model only as one name.

Only a pair that is plainly a whole name is read: it follows a
determiner and ends the phrase (the end of the clause, or a word that
cannot be part of a name). "the cup gently", "the keys real quick" and
"the cup sitting there" name no pair.
"""

from __future__ import annotations

import itertools
import re
from collections import Counter
from collections.abc import Collection

from agent.corrections import MARKERS

# Words that come before a thing's name and are never one ("approach a" from "move to the right a bit").
DETERMINERS = ("the", "a", "an", "some", "that", "this", "my", "your")
# Words of English's closed classes (pronouns, prepositions, conjunctions, auxiliaries, a few adverbs
# and quantifiers): never a word of a thing's name, so one after a pair ends it.
FUNCTION_WORDS = frozenset({"i", "me", "you", "he", "him", "she", "her", "it", "we", "us", "they", "them", "my",
                            "your", "his", "its", "our", "their", "this", "that", "these", "those", "there", "here",
                            "to", "from", "on", "in", "of", "at", "by", "with", "for", "into", "onto", "over",
                            "under", "near", "behind", "beside", "between", "next", "off", "out", "up", "down",
                            "through", "across", "around", "past", "toward", "towards", "about", "after", "before",
                            "against", "along", "and", "or", "but", "then", "so", "if", "when", "while", "because",
                            "once", "until", "unless", "than", "is", "are", "was", "were", "be", "been", "am", "do",
                            "does", "did", "has", "have", "had", "can", "could", "will", "would", "should", "may",
                            "might", "must", "please", "now", "again", "too", "also", "just", "very", "really",
                            "only", "already", "still", "even", "first", "last", "back", "away", "instead", "though",
                            "anyway", "all", "both",
                            "each", "every", "any", "other", "another", "same", "such", "one", "ones", "thanks",
                            "thank", "ok", "okay", "um", "uh", "hmm", "yes", "no", "not"}
                           # The words of a self-correction ("the red cup, wait, the blue cup").
                           | {word for marker in MARKERS for word in marker.split()})
# Nouns of place, amount and shape a task says that are never the object a skill acts on.
NOT_NAMES = frozenset({"left", "right", "start", "origin", "beginning", "way", "same", "other", "front",
                       "back", "end", "middle", "centre", "center", "robot", "side", "distance", "time", "times",
                       "little", "bit", "square", "triangle", "circle", "full", "long", "few", "couple",
                       "point", "position", "spot", "area", "room", "around", "head", "camera"})
# A closed-class word that is also a thing's last word ("the watering can", "the trash can"); a
# subject or verb after it makes it the auxiliary ("the cup can you grab").
_ALSO_NOUNS = frozenset({"can"})
_AFTER_AUXILIARY = frozenset({"i", "you", "he", "she", "it", "we", "they", "be", "do", "have", "not", "also",
                              "just", "really", "only", "still", "even", "already", "now"})
_PAIR = re.compile(rf"\b(?:{'|'.join(DETERMINERS)}) (?=([a-z]+) ([a-z]+)\b(?: ([a-z]+))?)")
# Endings of words that describe how or what is happening, not what a thing is called.
_NOT_NAME_ENDINGS = ("ly", "ing")


def said_only_in_pairs(text: str, not_names: Collection[str] = ()) -> frozenset[str]:
    """The words of the pairs `text` names things by that it never says on their own ("the red cup")."""
    return _only_in(name_pairs(text, not_names), text)


def _only_in(pairs: list[tuple[str, str]], text: str) -> frozenset[str]:
    inside = Counter(word for pair in pairs for word in pair)
    said = Counter(re.findall(r"[a-z]+", text.lower()))
    return frozenset(word for word, count in inside.items() if said[word] <= count)


def name_pairs(text: str, not_names: Collection[str] = ()) -> list[tuple[str, str]]:
    """The pairs of words `text` names things by ("the red cup" -> ("red", "cup")), each time said.

    `not_names` are words that never name a thing here (the robot's skill
    and direction words: "the left cup" is a cup).
    """
    never = FUNCTION_WORDS | NOT_NAMES | set(DETERMINERS) | set(not_names)
    pairs = []
    for m in _PAIR.finditer(text.lower()):
        first, second, after = m.groups()
        noun = second in _ALSO_NOUNS and after not in _AFTER_AUXILIARY
        if (first in never or (second in never and not noun) or second.endswith(_NOT_NAME_ENDINGS)
                or (after is not None and after not in never)):
            continue
        pairs.append((first, second))
    return pairs


def offered_names(text: str, not_names: Collection[str] = ()) -> tuple[str, ...]:
    """The words and pairs of words (`water_bottle`) of a whole task that may name the object a skill acts
    on, in the order said; the model chooses among them.

    Any word may ("pick up the book gently" is `book`), but a word of a pair that is plainly one name
    is offered only in the pair: a model trained on one-word names would keep one word of "the red
    cup" and lose which thing was meant. A closed-class word ("and", "it", "instead") names nothing
    unless a determiner says it does ("grasp the can"): offered, the model wrote `approach bottle_and;`
    for "the water bottle and pick it up". `not_names` as for `name_pairs`.
    """
    found = name_pairs(text, not_names)
    in_pairs = _only_in(found, text)
    said = re.findall(r"[a-z]+", text.lower())
    named = [word not in NOT_NAMES and word not in DETERMINERS and (word not in FUNCTION_WORDS or before in DETERMINERS)
             for before, word in zip(["", *said], said, strict=False)]
    words = [word for word, ok in zip(said, named, strict=True) if ok and word not in in_pairs]
    pairs = [f"{a}_{b}" for (a, b), ok in zip(itertools.pairwise(said), itertools.pairwise(named), strict=False)
             if all(ok)] + [f"{a}_{b}" for a, b in found]
    return tuple(dict.fromkeys((*words, *pairs)))
