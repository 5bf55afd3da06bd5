"""Which pairs of words name one thing: the translator offers them to the model only whole."""

import pytest

from agent.translate.names import name_pairs, said_only_in_pairs


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
