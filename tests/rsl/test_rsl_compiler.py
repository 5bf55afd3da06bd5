"""What a clean program compiles to."""

from __future__ import annotations

import dataclasses

import pytest

from rsl.compiler import compile_program
from rsl.plan import Command, ObjectRef, Plan, Quantity


def test_plan_is_typed_immutable_and_keeps_positions(profile):
    source = "// drive\nforward 1.5;  turnleft .5;\n/* block\n comment */ goto -1, 2e0;\napproach table;\nperceive;"
    result = compile_program(source, profile)
    assert result.ok and result.diagnostics == ()
    plan = result.plan
    assert isinstance(plan, Plan) and len(plan) == 5
    assert plan.commands[0] == Command("forward", (Quantity(1.5, "m"),), 2, 1)
    assert plan.commands[1] == Command("turnleft", (Quantity(0.5, "rad"),), 2, 15)
    assert plan.commands[2].args == (Quantity(-1.0, "m"), Quantity(2.0, "m"))
    assert plan.commands[3].object() == "table" and plan.commands[3].args == (ObjectRef("table"),)
    assert plan.commands[4].args == ()
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.commands[0].skill = "backward"  # type: ignore[misc]
    assert plan.to_rsl() == ("forward 1.5;\nturnleft 0.5;\ngoto -1, 2;\napproach table;\nperceive;\n")


def test_whitespace_and_newlines_are_free(profile):
    spaced = compile_program("goto\n  1 ,\n\t2\n;", profile)
    assert spaced.ok and spaced.plan.to_rsl() == "goto 1, 2;\n"


def test_canonical_text_round_trips(profile):
    plan = compile_program("forward 0.25; lookleft 1.5708; grasp red_ball;", profile).plan
    again = compile_program(plan.to_rsl(), profile).plan
    assert [(c.skill, c.args) for c in again] == [(c.skill, c.args) for c in plan]


def test_plan_dicts_round_trip(profile):
    plan = compile_program("goto 1.5, -2; grasp cup;", profile).plan
    assert [Command.from_dict(c) for c in plan.to_list()] == list(plan.commands)


def test_empty_statements_are_allowed_as_in_c(profile):
    result = compile_program(";forward 1;;", profile)
    assert result.ok and len(result.plan) == 1


def test_empty_program_is_clean_and_empty(profile):
    result = compile_program("// nothing to do\n", profile)
    assert result.ok and len(result.plan) == 0
