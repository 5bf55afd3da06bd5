"""Words that name a person: whom a task is said to when it opens with one ("Mia, look up").

A person in the room hears the same imperatives the robot does ("Dad, turn
left at the lights", "kids, go back to the start"), and the small model
reads the imperative, not whom it was said to. A given name or a word for
family or a loved one names someone; a word anyone may be called by
("buddy", "mate") names nobody in particular, and people call robots so too.
"""

from __future__ import annotations

import functools
from importlib import resources

# Words for family and loved ones, said to call someone: a person, never a robot's name.
_FAMILY = frozenset({"mum", "mom", "mummy", "mommy", "mama", "mam", "dad", "daddy", "papa", "mother", "father",
                     "grandma", "grandpa", "granny", "grandad", "granddad", "gran", "nana", "nan", "auntie", "aunty",
                     "aunt", "uncle", "son", "daughter", "sis", "honey", "sweetie", "sweetheart", "darling", "babe",
                     "baby", "love", "kids", "children", "everyone", "everybody", "folks", "guys"})
# Words anyone may be called by, a robot as well: they name nobody in particular.
_ANYONE = frozenset({"buddy", "bud", "pal", "mate", "friend", "dude", "man", "boss", "chief", "champ", "sport",
                     "partner", "bro", "fella"})


@functools.cache
def _given_names() -> frozenset[str]:
    text = (resources.files("agent.translate") / "given_names.txt").read_text("utf-8")
    return frozenset(line for line in text.splitlines() if line and not line.startswith("#"))


def names_a_person(word: str) -> bool:
    """Whether the lower-case `word`, said to call someone, names a person: a given name or a word for
    family or a loved one."""
    return word not in _ANYONE and (word in _FAMILY or word in _given_names())
