"""Which pairs of words name one thing: the translator offers them to the model only whole."""

import pytest

from agent.translate.names import name_pairs, offered_names, said_only_in_pairs
from agent.translate.translator import Options, Translator
from rsl.profile import load_profile


@pytest.mark.parametrize(("text", "pairs"), [
    ("go over to the red cup", (("red", "cup"),)),
    ("pick up the water bottle please", (("water", "bottle"),)),
    ("go to the kitchen table and have a look around", (("kitchen", "table"),)),
    ("head to the charging station, then stop", (("charging", "station"),)),
    ("grab the red cup, not the blue cup", (("red", "cup"), ("blue", "cup"))),
    # A word after the name that tells how, or a third word: no pair is plainly one name.
    ("pick up the book gently", ()),
    ("grab the keys real quick", ()),
    ("grab the cup sitting on the table", ()),
    ("go to the chair near the window", ()),
    # "can" ends a name when no subject or verb follows it.
    ("go get the watering can", (("watering", "can"),)),
    ("take the trash can and then come back", (("trash", "can"),)),
    ("pick up the cup can you", ()),
    ("the box can be opened", ()),
    # Amounts, places and the robot's own words are never a name.
    ("move forward a little further", ()),
    ("turn the robot around", ()),
    ("look at the left cup", ()),
])
def test_a_pair_is_read_only_when_it_is_plainly_one_name(text: str, pairs: tuple[tuple[str, str], ...]) -> None:
    assert tuple(name_pairs(text, not_names={"left", "right"})) == pairs


def test_a_word_said_on_its_own_as_well_is_not_only_in_a_pair() -> None:
    assert said_only_in_pairs("go to the red cup") == {"red", "cup"}
    assert said_only_in_pairs("go to the red cup, then pick up the cup") == {"red"}
    assert said_only_in_pairs("go to the red cup, then the red cup again") == {"red", "cup"}


@pytest.mark.parametrize(("text", "offered"), [
    # A pair plainly one name is offered whole; its words alone are not.
    ("pick up the red cup", ("pick", "red_cup")),
    # A closed-class word names nothing, alone or in a pair ...
    ("go over to the water bottle and pick it up", ("go", "pick", "water_bottle")),
    ("fetch the orange instead", ("fetch", "orange")),
    # ... unless a determiner says it does.
    ("grasp the can", ("grasp", "can")),
    # ... or it ends a name.
    ("go to the trash can and then return home", ("go", "return", "home", "return_home", "trash_can")),
    # Other words stay, alone and with their neighbours: the model picks.
    ("pick up the book gently", ("pick", "book", "gently", "book_gently")),
    # A self-correction's words name nothing.
    ("pick up the red cup, wait, the blue cup", ("pick", "red_cup", "blue_cup")),
])
def test_a_whole_task_offers_the_words_that_may_name_a_thing(text: str, offered: tuple[str, ...]) -> None:
    assert offered_names(text, not_names={"left", "right"}) == offered


class _NoEngine:
    def close(self) -> None: ...


@pytest.mark.parametrize(("clause", "objects"), [
    ("pick up the cup please", ("cup",)),
    ("grasp the cup now", ("cup",)),
    ("approach the red cup", ("cup", "red_cup")),
])
def test_a_clause_offers_its_object_without_the_words_said_after_it(clause: str, objects: tuple[str, ...]) -> None:
    # One clause at a time (the base model's mode): an object phrase ends at any closed-class word.
    translator = Translator(load_profile(), _NoEngine(), "none", Options(split_clauses=True))  # type: ignore[arg-type]
    assert translator._task_objects(clause) == objects
