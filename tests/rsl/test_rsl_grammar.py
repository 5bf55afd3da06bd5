"""The exported GBNF grammar agrees with the parser, both ways."""

from __future__ import annotations

import random

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rsl.compiler import compile_program
from rsl.grammar import to_gbnf
from rsl.plan import Command, ObjectRef, Plan, Quantity, format_number
from tests.rsl import gbnf


@pytest.fixture(scope="module")
def grammar(profile):
    return gbnf.parse(to_gbnf(profile))


def test_llama_cpp_accepts_the_grammar(profile):
    llama_cpp = pytest.importorskip("llama_cpp")
    for objects in (None, ["cup", "table"], []):
        assert llama_cpp.LlamaGrammar.from_string(to_gbnf(profile, objects), verbose=False) is not None
    narrowed = to_gbnf(profile, ["cup"], keywords=["grasp", "goto", "turnleft"], max_statements=3, refusal=True,
                       numbers={"goto#0": ["-2", "1.5"], "rad": ["1.5708"]})
    assert llama_cpp.LlamaGrammar.from_string(narrowed, verbose=False) is not None


def test_thousands_of_programs_drawn_from_the_grammar_all_parse(profile, grammar):
    rng = random.Random(1234)
    for _ in range(3000):
        text = grammar.sample(rng)
        assert text.endswith("\n\n")
        result = compile_program(text, profile)
        syntax = [d for d in result.diagnostics if not d.code.is_semantic]
        assert syntax == [], (text, [d.brief() for d in syntax])


def test_generation_can_stop_on_a_blank_line_and_only_there(grammar):
    pattern = grammar.regex()
    assert pattern.fullmatch("forward 1;\n\n")
    assert pattern.fullmatch("perceive;\ngoto -1.5, 0;\n\n")
    assert not pattern.fullmatch("forward 1;\n")
    assert not pattern.fullmatch("forward 1;\n\n\n")
    assert not pattern.fullmatch("forward 1;\n\nforward 1;\n\n")


def _plans(profile, objects=("cup", "table", "red_ball")):
    def command(skill):
        args = []
        for param in skill.params:
            if param.kind == "object":
                args.append(st.sampled_from(objects).map(ObjectRef))
            else:
                low = param.min if param.min is not None else 0.01
                args.append(st.floats(low, param.max).map(
                    lambda v, unit=param.unit: Quantity(float(format_number(v)), unit)))
        return st.tuples(*args).map(lambda a, k=skill.keyword: Command(k, a, 0, 0))

    commands = st.one_of([command(s) for s in profile.skills])
    return st.lists(commands, min_size=1, max_size=profile.max_statements).map(
        lambda cs: Plan(tuple(cs), profile.name))


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_random_valid_plans_printed_canonically_match_the_grammar(profile, grammar, data):
    plan = data.draw(_plans(profile))
    text = plan.to_rsl() + "\n"
    assert grammar.regex().fullmatch(text), text
    result = compile_program(text, profile)
    assert result.ok, [d.brief() for d in result.diagnostics]
    assert [c.args for c in result.plan] == [c.args for c in plan]


def test_grammar_narrowed_to_known_objects(profile):
    narrowed = gbnf.parse(to_gbnf(profile, ["cup", "table"])).regex()
    assert narrowed.fullmatch("grasp cup;\n\n")
    assert not narrowed.fullmatch("grasp sofa;\n\n")
    no_objects = to_gbnf(profile, [])
    assert "grasp" not in no_objects and "approach" not in no_objects and "forward" in no_objects


def test_grammar_rejects_object_names_that_are_not_identifiers(profile):
    with pytest.raises(ValueError, match="C identifiers"):
        to_gbnf(profile, ['cup" | "x'])
