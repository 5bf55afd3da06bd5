"""The normalizer's output format is a contract with the adapter's training data."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from agent.normalize import normalize_task


@pytest.mark.parametrize(
    ("task", "expected"),
    [
        ("Move forward two meters, then grasp the cup.", "move forward 2 m, then grasp the cup"),
        ("uh please turn left ninety degrees", "turn left 1.5708 rad"),
        ("go forward to meters", "go forward 2 m"),
        ("turn right for times", "turn right 4 times"),
        ("move half a meter forward", "move 0.5 m forward"),
        ("move back 50cm", "move back 0.5 m"),
        ("drive two and a half meters", "drive 2.5 m"),
        ("rotate 45°", "rotate 0.7854 rad"),
        ("go to minus three point five, two", "go to -3.5, 2"),
        ("go to 1, -2", "go to 1, -2"),
        ("Could you go a meter and a half forward?", "go 1.5 m forward"),
        ("Can you see the cup?", "can you see the cup"),
        ("could you please see what is in front of you", "see what is in front of you"),
        ("spin two full turns", "spin 12.5664 rad"),
        ("turn half a turn", "turn 3.1416 rad"),
        ("move 3 feet", "move 0.9144 m"),
        ("one hundred and twenty centimeters", "1.2 m"),
        ("twenty-five degrees", "0.4363 rad"),
        ("move forward 1.5m", "move forward 1.5 m"),
        ("move forward one point five meters", "move forward 1.5 m"),
        ("do it twice", "do it 2 times"),
        ("Turn LEFT 3.14159 radians!", "turn left 3.1416 rad"),
        ("move forward 300 millimetres", "move forward 0.3 m"),
        ("drive to the point -2, 1.5", "drive to the point -2, 1.5"),
        ("drive point five meters", "drive 0.5 m"),
        ("go to the point two, five", "go to the point 2, 5"),
        # Two numbers after "point" are a place, as a recognizer writes it, comma and all.
        ("er go to point three comma minus two", "go to point 3, -2"),
        ("go to two comma three", "go to 2, 3"),
        # A recognizer's homophone of a number is one in a point, right after a word naming the place ...
        ("drive to the point for comma one", "drive to the point 4, 1"),
        ("head to the spot at too comma for", "head to the spot at 2, 4"),
        ("go to point for comma too and then grab the cup", "go to point 4, 2 and then grab the cup"),
        # ... and stays a word elsewhere, next to a comma or not.
        ("look for, 2 cups", "look for, 2 cups"),
        ("go to 1, for the cup", "go to 1, for the cup"),
        ("go to 3 comma x", "go to 3 comma x"),
        ("drive point five meters, and then turn", "drive 0.5 m, and then turn"),
        ("do one complete rotation", "do 6.2832 rad"),
        ("spin a whole turn", "spin 6.2832 rad"),
        # A turn named by its degrees after an article, said as hundreds or in digits.
        ("pull a one eighty", "pull turn 3.1416 rad"),
        ("do a 360, then stop", "do turn 6.2832 rad, then stop"),
        ("turn two seventy degrees", "turn 4.7124 rad"),
        ("take a 20 cm step forward", "take a 0.2 m step forward"),
        # A U-turn is half a turn, as exact as "half a turn".
        ("make a u-turn", "make turn 3.1416 rad"),
        ("do a U turn to the right", "do turn 3.1416 rad to the right"),
        ("pull a uturn then stop", "pull turn 3.1416 rad then stop"),
        # Thanks and corrections carry meaning the model needs: a closing is no task, "i mean" corrects.
        ("cheers, thanks, that's all", "cheers, thanks, that's all"),
        ("turn left, i mean right", "turn left, i mean right"),
        # A fraction of a unit or of a turn is worked out, as "half a meter" is.
        ("turn left a third of a turn", "turn left 2.0944 rad"),
        ("move three quarters of a meter", "move 0.75 m"),
        ("spin two thirds of a turn", "spin 4.1888 rad"),
        ("go forward one fifth of a meter", "go forward 0.2 m"),
        ("an eighth of a circle", "0.7854 rad"),
        # A bare number that corrects an amount is in the amount's unit.
        ("turn left 30 degrees, no, 60", "turn left 0.5236 rad, no, 1.0472 rad"),
        # ... even across an ellipsis and a dropped filler, which leave several commas.
        ("Turn right thirty degrees... uh no, sixty.", "turn right 0.5236 rad, no, 1.0472 rad"),
        ("move 50 centimeters, make that 80", "move 0.5 m, make that 0.8 m"),
        ("go forward three meters, no wait, four", "go forward 3 m, no wait, 4 m"),
        ("turn left 90 degrees, no, 2 times", "turn left 1.5708 rad, no, 2 times"),
        ("drive 2 meters, no, 3 feet", "drive 2 m, no, 0.9144 m"),
        # ... after a run of markers too.
        ("turn right ninety degrees, no, make that forty-five", "turn right 1.5708 rad, no, make that 0.7854 rad"),
        # ... with the way it goes said between, and after "make it".
        ("Forty-five degrees to the left. Make that sixty.", "0.7854 rad to the left, make that 1.0472 rad"),
        ("Forward 50 centimetres, no wait, make it 30.", "forward 0.5 m, no wait, make it 0.3 m"),
        ("turn left 90 degrees and go forward, no, 2", "turn left 1.5708 rad and go forward, no, 2"),
        # A bare number corrected by an amount takes the amount's unit; a bare number that is not, stays bare.
        ("go forward three, sorry, four metres", "go forward 3 m, sorry, 4 m"),
        ("turn left twenty five, sorry, thirty degrees", "turn left 0.4363 rad, sorry, 0.5236 rad"),
        ("move 1, then 2 m", "move 1, then 2 m"),
        ("go to three, no, four, five", "go to 3, no, 4, 5"),
        # A bare number after a turn's way, too large to be radians, is degrees.
        ("turn left 90", "turn left 1.5708 rad"),
        ("rotate clockwise by forty five", "rotate clockwise by 0.7854 rad"),
        ("go forward 2 then turn right 180", "go forward 2 then turn right 3.1416 rad"),
        # One length said in two units is one amount: their sum.
        ("roll forward two feet six inches", "roll forward 0.762 m"),
        ("move forward one metre and twenty centimetres", "move forward 1.2 m"),
        ("back up a meter and a half and ten centimeters", "back up 1.6 m"),
        # ... but not two lengths, nor a larger unit after a smaller one.
        ("forward 2 m and 3 m", "forward 2 m and 3 m"),
        ("forward 1 m and back 20 cm", "forward 1 m and back 0.2 m"),
        ("go 30 cm and 2 m", "go 0.3 m and 2 m"),
    ],
)
def test_normalize_converts_numbers_units_and_fillers(task: str, expected: str) -> None:
    assert normalize_task(task) == expected


@pytest.mark.parametrize(
    "task",
    ["look for the cup", "go to the door", "turn a little", "grasp the red cup", "make a turn",
     "grab a third of the cups", "turn left 3", "turn left 10 times", "turn right 400", "go left 10, 5"],
)
def test_normalize_keeps_words_that_only_sound_like_numbers(task: str) -> None:
    assert normalize_task(task) == task


@pytest.mark.parametrize(
    ("task", "expected"),
    [("turn a hundred and eighty degrees", "turn 3.1416 rad"), ("turn a hundred eighty degrees", "turn 3.1416 rad"),
     ("go a hundred and fifty centimetres", "go 1.5 m"), ("go one thousand millimetres", "go 1 m"),
     ("go a thousand two hundred and fifty millimetres", "go 1.25 m"),
     ("go forward nought point five metres", "go forward 0.5 m")],
)
def test_normalize_reads_a_hundred_and_thousands_as_one_number(task: str, expected: str) -> None:
    assert normalize_task(task) == expected


@pytest.mark.parametrize(
    ("task", "expected"),
    [("go forward a metre fifty", "go forward 1.5 m"), ("move forward two foot six", "move forward 0.762 m"),
     ("go forward one metre twenty then turn left", "go forward 1.2 m then turn left"),
     ("go forward a metre 5 times", "go forward 1 m 5 times"), ("go forward two feet 14", "go forward 0.6096 m 14")],
)
def test_normalize_reads_a_smaller_unit_left_unsaid(task: str, expected: str) -> None:
    assert normalize_task(task) == expected


@pytest.mark.parametrize(("task", "expected"), [("go too the fridge", "go to the fridge"),
                                                ("go two the kitchen", "go to the kitchen")])
def test_normalize_hears_to_where_a_number_cannot_be(task: str, expected: str) -> None:
    assert normalize_task(task) == expected


@pytest.mark.parametrize(
    ("task", "expected"),
    [("turn left for ty five degrees", "turn left 0.7854 rad"), ("go six ty centimetres", "go 0.6 m"),
     ("turn fif teen degrees", "turn 0.2618 rad"), ("go for teen centimetres", "go 0.14 m"),
     ("i have ty", "i have ty")],
)
def test_normalize_joins_a_number_word_heard_in_two(task: str, expected: str) -> None:
    assert normalize_task(task) == expected


@pytest.mark.parametrize(
    ("task", "expected"),
    [("uh turn a round", "turn around"), ("turn a round to the right", "turn around to the right"),
     ("walk to wards the door", "walk towards the door"),
     ("grab a round box", "grab a round box"), ("pan a head left", "pan a head left")],
)
def test_normalize_joins_a_word_heard_in_two(task: str, expected: str) -> None:
    assert normalize_task(task) == expected


def test_normalize_is_idempotent_on_its_own_output() -> None:
    for task in ["move forward 2 m, then grasp the cup", "turn left 1.5708 rad", "go to -3.5, 2"]:
        assert normalize_task(normalize_task(task)) == normalize_task(task)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.sampled_from(["point", "minus", "half", "a", "and", "to", "for", "two", "five", "m",
                                 "degrees", "turns", "full", "1.5", "-", ",", "the", "twenty", "hundred",
                                 "quarter", "of", "times", "."]), max_size=12))
def test_normalize_terminates_on_any_word_salad(words: list[str]) -> None:
    assert isinstance(normalize_task(" ".join(words)), str)


def test_normalize_of_empty_or_filler_only_text_is_empty() -> None:
    assert normalize_task("") == ""
    assert normalize_task("uh, um... please") == ""
