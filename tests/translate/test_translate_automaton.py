"""The sampling automaton must accept exactly the canonical language the compiler and GBNF export agree on."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from agent.translate.automaton import START, RslAutomaton
from agent.translate.clauses import split_clauses
from rsl.compiler import compile_program
from rsl.profile import Profile


def test_accepts_canonical_programs_and_rejects_others(profile: Profile) -> None:
    automaton = RslAutomaton(profile)
    for good in ["forward 2;\n\n", "goto -1.5, 0;\nperceive;\n\n", "grasp red_cup;\nturnleft 1.5708;\n\n"]:
        assert automaton.accepts(good), good
        assert compile_program(good, profile).ok
    for bad in ["forward 2;\n", "Forward 2;\n\n", "forward 2.12345;\n\n", "forward -1;\n\n",
                "forward 100;\n\n", "perceive 1;\n\n", "goto 1 2;\n\n", "\n"]:
        assert not automaton.accepts(bad), bad


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_every_accepted_program_parses(profile: Profile, data: st.DataObject) -> None:
    """Walk random allowed characters to the end: whatever the automaton accepts must parse."""
    automaton = RslAutomaton(profile)
    alphabet = sorted(set("abcdefghijklmnopqrstuvwxyz0123456789_.,;- \n"))
    state, text = START, ""
    for _ in range(80):
        choices = [c for c in alphabet if automaton.step(state, c) is not None]
        char = data.draw(st.sampled_from(choices))
        text += char
        state = automaton.step(state, char)
        assert state is not None
        if state == ("END",):
            break
    if state == ("END",):
        diagnostics = compile_program(text, profile).diagnostics
        assert all(d.code.is_semantic for d in diagnostics), (text, diagnostics)


def test_narrowing_limits_objects_and_numbers(profile: Profile) -> None:
    automaton = RslAutomaton(profile, objects=["cup"], numbers={"m": {"2", "-2", "0"}})
    assert automaton.accepts("grasp cup;\nforward 2;\ngoto -2, 0;\n\n")
    assert not automaton.accepts("grasp mug;\n\n")
    assert not automaton.accepts("forward 3;\n\n")
    assert not automaton.accepts("forward -2;\n\n")


def test_empty_object_list_drops_object_skills(profile: Profile) -> None:
    automaton = RslAutomaton(profile, objects=[])
    assert "grasp" not in automaton.skills and "forward" in automaton.skills


def test_clauses_split_on_actions_not_on_coordinates(profile: Profile) -> None:
    clauses = split_clauses("go to 1, 2 and grasp the ball, then turn left 3 times", profile)
    assert [c.text for c in clauses] == ["go to 1, 2", "grasp the ball", "turn left"]
    assert clauses[2].repeat == 3
    pronoun = split_clauses("approach the red cup and pick it up", profile)
    assert pronoun[1].text == "pick the red cup up"
    repeat = split_clauses("drive forward 1 m and turn left 1.5708 rad, repeat 4 times", profile)
    assert repeat[-1].repeat_previous and repeat[-1].repeat == 4
    square = split_clauses("go to 1, 1, perceive, then drive in a square with 2 m sides", profile)
    assert [c.text for c in square[:4]] == ["go to 1, 1", "perceive", "drive forward 2 m", "turn left 1.5708 rad"]
    assert square[-1].repeat_previous and square[-1].repeat == 4 and square[-1].span == 2


def test_it_never_stands_for_a_place_or_amount(profile: Profile) -> None:
    # The splitter reads "it" with the shared list of words that name no thing (names.NOT_NAMES).
    clauses = split_clauses("go over to the spot, then look at it", profile)
    assert [c.text for c in clauses] == ["go over to the spot", "look at it"]
