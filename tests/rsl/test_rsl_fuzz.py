"""Arbitrary text never crashes the compiler: it gives a plan or diagnostics."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from rsl.compiler import compile_program

RSL_ALPHABET = st.sampled_from(list("forwadbcktulpinmgesh ;,./*-+0123456789\n\t$#ABCDE_"))
RSL_LIKE = st.lists(st.one_of(RSL_ALPHABET, st.sampled_from(
    ["forward", "goto", "grasp", "perceive", "/*", "*/", "//", "1.5", "-2", "1e", ";", ","])), max_size=80
).map("".join)


def _check(profile, text):
    result = compile_program(text, profile, known_objects=["cup"])
    assert (result.plan is not None) == (not result.diagnostics)
    for diagnostic in result.diagnostics:
        assert diagnostic.line >= 1 and diagnostic.column >= 1
        assert diagnostic.message
        assert diagnostic.source_line == text.split("\n")[diagnostic.line - 1]
        diagnostic.render()


@settings(max_examples=1500, deadline=None)
@given(text=st.text(max_size=200))
def test_arbitrary_unicode_never_crashes(profile, text):
    _check(profile, text)


@settings(max_examples=1500, deadline=None)
@given(text=RSL_LIKE)
def test_rsl_like_noise_never_crashes(profile, text):
    _check(profile, text)


@settings(max_examples=1500, deadline=None)
@given(text=st.one_of(RSL_LIKE, st.text(max_size=120)))
def test_tokens_cover_every_character_that_is_not_whitespace(text):
    from rsl.lexer import SourceMap, tokenize

    lines = SourceMap(text)
    covered = [False] * len(text)
    for token in tokenize(text, lines):
        assert text[token.offset:token.offset + len(token.text)] == token.text
        assert lines.position(token.offset) == (token.line, token.column)
        for i in range(token.offset, token.offset + len(token.text)):
            covered[i] = True
    assert all(covered[i] or text[i] in " \t\r\n\f\v" for i in range(len(text))), text
