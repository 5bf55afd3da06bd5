"""Each of the nine syntax categories, and the semantic errors, for its example."""

from __future__ import annotations

import pytest

from rsl.compiler import compile_program
from rsl.diagnostics import Code

NINE = [
    ("APPROACH table;", Code.KEYWORD_CASE, 1, 1, "APPROACH", "write `approach`"),
    ("approach 3apple;", Code.ILLEGAL_IDENTIFIER, 1, 10, "3apple", "did you mean `apple`"),
    ("forward 123.23.45;", Code.ILLEGAL_NUMBER, 1, 9, "123.23.45", "is not a number"),
    ("$forward 1;", Code.ILLEGAL_CHARACTER, 1, 1, "$", "remove it"),
    ("/ This is a comment", Code.BAD_COMMENT, 1, 1, "/", "write `//`"),
    ("move 1.5;", Code.UNKNOWN_COMMAND, 1, 1, "move", "did you mean `forward`?"),
    ("forward table;", Code.PARAMETER_TYPE, 1, 9, "table", "expects a number"),
    ("goto 1;", Code.PARAMETER_COUNT, 1, 1, "goto", "takes 2 arguments"),
    ("approach table", Code.MISSING_SEMICOLON, 1, 10, "table", "missing `;` after `table`"),
]


@pytest.mark.parametrize(("source", "code", "line", "column", "token", "advice"), NINE,
                         ids=[c[1].title for c in NINE])
def test_each_syntax_category_is_reported_exactly(profile, source, code, line, column, token, advice):
    result = compile_program(source, profile)
    assert not result.ok and result.plan is None
    assert [d.code for d in result.diagnostics] == [code]
    diagnostic = result.diagnostics[0]
    assert (diagnostic.line, diagnostic.column, diagnostic.token) == (line, column, token)
    assert advice in diagnostic.message
    assert diagnostic.source_line == source.splitlines()[0]


def test_rendering_points_at_the_token_with_a_caret_underline(profile):
    diagnostic = compile_program("forward 1;\n  grab cup;\n", profile).diagnostics[0]
    rendered = diagnostic.render()
    assert rendered.splitlines() == [
        "error[E006]: unknown command",
        " --> line 2, column 3",
        "  |",
        "2 |   grab cup;",
        "  |   ^^^^ `grab` is not a command; did you mean `grasp`? "
        "(`grasp OBJECT;`: pick up an object that is within reach of the gripper.)",
    ]
    assert diagnostic.brief().startswith("line 2, column 3: `grab` is not a command")


SEMANTIC = [
    ("forward 100;", Code.OUT_OF_RANGE, "between 0.01 and 10 m"),
    ("forward -1;", Code.NOT_POSITIVE, "use `backward 1;`"),
    ("turnleft 0;", Code.NOT_POSITIVE, "positive angle"),
    ("goto 20, 1;", Code.OUTSIDE_WORKSPACE, "x must be between -10 and 10"),
    ("goto 1, -11;", Code.OUTSIDE_WORKSPACE, "y must be between"),
    ("approach sofa;", Code.UNKNOWN_OBJECT, "known objects are `cup`, `table`"),
    ("grasp cups;", Code.UNKNOWN_OBJECT, "did you mean `cup`?"),
]


@pytest.mark.parametrize(("source", "code", "advice"), SEMANTIC, ids=[s[0] for s in SEMANTIC])
def test_semantic_errors(profile, source, code, advice):
    result = compile_program(source, profile, known_objects=["table", "cup"])
    assert [d.code for d in result.diagnostics] == [code]
    assert advice in result.diagnostics[0].message


def test_program_longer_than_the_profile_limit(profile):
    source = "perceive;\n" * (profile.max_statements + 1)
    result = compile_program(source, profile)
    assert [d.code for d in result.diagnostics] == [Code.TOO_LONG]
    assert result.diagnostics[0].line == profile.max_statements + 1
    assert compile_program("perceive;\n" * profile.max_statements, profile).ok


def test_every_error_in_a_program_is_reported_in_one_pass(profile):
    source = "\n".join([
        "forward 1;",
        "APPROACH table;",
        "move 2;",
        "goto 1;",
        "turnleft 1.5708",
        "grasp 3cup;",
        "lookup 0.3; $",
        "forward 123.23.45;",
        "forward table;",
        "perceive;",
    ])
    result = compile_program(source, profile)
    assert [(d.line, d.code) for d in result.diagnostics] == [
        (2, Code.KEYWORD_CASE),
        (3, Code.UNKNOWN_COMMAND),
        (4, Code.PARAMETER_COUNT),
        (5, Code.MISSING_SEMICOLON),
        (6, Code.ILLEGAL_IDENTIFIER),
        (7, Code.ILLEGAL_CHARACTER),
        (8, Code.ILLEGAL_NUMBER),
        (9, Code.PARAMETER_TYPE),
    ]


def test_missing_comma_and_stray_comma(profile):
    assert [d.code for d in compile_program("goto 1 2;", profile).diagnostics] == [Code.MISSING_COMMA]
    assert [d.code for d in compile_program("goto 1,, 2;", profile).diagnostics] == [Code.MISSING_COMMA]


def test_missing_semicolon_between_statements_on_one_line(profile):
    result = compile_program("forward 1 turnleft 2;", profile)
    assert [(d.code, d.token) for d in result.diagnostics] == [(Code.MISSING_SEMICOLON, "1")]


def test_unclosed_block_comment(profile):
    result = compile_program("forward 1;\n/* never closed\nturnleft 1;", profile)
    assert [(d.code, d.line) for d in result.diagnostics] == [(Code.BAD_COMMENT, 2)]
    assert "never closed" in result.diagnostics[0].message


def test_unknown_word_with_no_near_match_lists_the_commands(profile):
    message = compile_program("xyzzy;", profile).diagnostics[0].message
    assert all(f"`{k}`" in message for k in profile.keywords)
