"""Every writer and reader of RSL accepts the same canonical language (`rsl.syntax`).

Random programs are drawn from each producer, under random narrowings: walks
of the decoding automaton, derivations of the GBNF grammar (read by the
independent reader in tests/rsl/gbnf.py, not by the code that wrote it), and
the training-data generator. Each program must be accepted by all the others:
the automaton character by character, the GBNF grammar, and the compiler.
"""

from __future__ import annotations

import json
import random
import threading
from http.server import BaseHTTPRequestHandler, HTTPServer

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from agent.adapter.data import generate
from agent.translate.automaton import END, START, RslAutomaton
from agent.translate.http import HttpEngine
from rsl.compiler import compile_program
from rsl.grammar import to_gbnf
from rsl.profile import Profile
from rsl.syntax import MAX_IDENTIFIER, NO_PROGRAM, syntax_of
from tests.rsl import gbnf

_SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@st.composite
def narrowings(draw: st.DrawFn, profile: Profile) -> dict:
    """Keyword arguments of `RslAutomaton`, `to_gbnf` and `syntax_of`, as the translator narrows."""
    keywords = draw(st.none() | st.lists(st.sampled_from(profile.keywords), min_size=1, unique=True))
    objects = draw(st.none() | st.lists(st.sampled_from(["cup", "red_cup", "table", "c", "_x9"]), unique=True))
    units = sorted({p.unit for s in profile.skills for p in s.params if p.kind == "number"})
    spellings = st.sets(st.sampled_from(["0", "1", "2", "-2", "0.5", "1.5708", "12.25", "-0.75"]), max_size=3)
    keys = st.sampled_from([*units, "goto#0", "goto#1", "turnleft:rad", "forward:m"])
    numbers = draw(st.none() | st.dictionaries(keys, spellings, max_size=3))
    kwargs = {"keywords": keywords, "objects": objects, "numbers": numbers,
              "max_statements": draw(st.none() | st.integers(1, 5)), "refusal": draw(st.booleans())}
    try:
        syntax_of(profile, **kwargs)
    except ValueError:
        kwargs["keywords"] = None  # the narrowing left no statement, as the translator would drop it
        kwargs["objects"] = objects or None
    return kwargs


def _syntax_clean(text: str, profile: Profile) -> None:
    """The compiler reads the program with no syntax error (ranges and objects are its other job)."""
    result = compile_program(text, profile)
    syntax = [d.brief() for d in result.diagnostics if not d.code.is_semantic]
    assert syntax == [], (text, syntax)


def _accepted_by_all(text: str, profile: Profile, automaton: RslAutomaton, grammar: gbnf.Grammar) -> None:
    assert automaton.accepts(text), text
    assert grammar.regex().fullmatch(text), text
    assert automaton.syntax.regex().fullmatch(text), text
    _syntax_clean(text, profile)


def _walk(automaton: RslAutomaton, rng: random.Random, alphabet: list[str]) -> str | None:
    """A random walk to the end, starting no statement past the cap; None when it runs too long."""
    state, text, statements = START, "", 0
    for _ in range(400):
        choices = [c for c in alphabet if automaton.step(state, c) is not None]
        if statements >= automaton.max_statements:
            choices = [c for c in choices if automaton.step(state, c) == END]
        assert choices, (text, state)
        char = rng.choice(choices)
        text += char
        state = automaton.step(state, char)  # type: ignore[assignment]
        statements += state == ("S", True)
        if state == END:
            return text
    return None


@_SETTINGS
@given(data=st.data())
def test_automaton_walks_are_accepted_by_the_grammar_and_the_compiler(profile: Profile, data: st.DataObject) -> None:
    kwargs = data.draw(narrowings(profile))
    automaton = RslAutomaton(profile, **kwargs)
    grammar = gbnf.parse(to_gbnf(profile, **kwargs))
    rng = data.draw(st.randoms(use_true_random=False))
    alphabet = sorted(set("abcdefghijklmnopqrstuvwxyzABCXYZ0123456789_.,;-/ \n"))
    for _ in range(5):
        text = _walk(automaton, rng, alphabet)
        if text is not None:
            _accepted_by_all(text, profile, automaton, grammar)


@_SETTINGS
@given(data=st.data())
def test_grammar_derivations_are_accepted_by_the_automaton_and_the_compiler(profile: Profile,
                                                                           data: st.DataObject) -> None:
    kwargs = data.draw(narrowings(profile))
    automaton = RslAutomaton(profile, **kwargs)
    # The automaton's own grammar (the one sent to HTTP endpoints) is the same text as the export.
    assert automaton.to_gbnf() == to_gbnf(profile, **kwargs)
    grammar = gbnf.parse(to_gbnf(profile, **kwargs))
    rng = data.draw(st.randoms(use_true_random=False))
    for repeat in (2, 8, MAX_IDENTIFIER + 8):  # long repeats reach the longest names and numbers
        for _ in range(4):
            _accepted_by_all(grammar.sample(rng, max_repeat=repeat), profile, automaton, grammar)


@pytest.fixture(scope="module")
def training_programs(profile: Profile) -> list[str]:
    return [pair.program + "\n" for pair in generate(profile, 400, seed=12)]


def test_training_programs_are_accepted_by_the_automaton_grammar_and_compiler(
        profile: Profile, training_programs: list[str]) -> None:
    automaton = RslAutomaton(profile, refusal=True)
    grammar = gbnf.parse(to_gbnf(profile, refusal=True))
    for text in [*training_programs, NO_PROGRAM + "\n\n"]:
        _accepted_by_all(text, profile, automaton, grammar)
        assert compile_program(text, profile).ok


@pytest.mark.parametrize("cap", [1, 3, None])
def test_the_statement_cap_holds_on_every_path(profile: Profile, cap: int | None) -> None:
    limit = cap or profile.max_statements
    automaton = RslAutomaton(profile, max_statements=cap)
    for grammar_text in (to_gbnf(profile, max_statements=cap), automaton.to_gbnf()):
        pattern = gbnf.parse(grammar_text).regex()
        assert pattern.fullmatch("perceive;\n" * limit + "\n")
        assert not pattern.fullmatch("perceive;\n" * (limit + 1) + "\n")
    assert automaton.accepts("perceive;\n" * limit + "\n")
    assert not automaton.accepts("perceive;\n" * (limit + 1) + "\n")
    if cap is None:
        assert compile_program("perceive;\n" * limit, profile).ok
        assert not compile_program("perceive;\n" * (limit + 1), profile).ok


def test_the_refusal_line_is_the_only_comment_in_the_canonical_language(profile: Profile) -> None:
    automaton = RslAutomaton(profile, refusal=True)
    assert not automaton.accepts("// hello\n\n")
    assert not automaton.accepts("forward 1; // go\n\n")
    assert not automaton.accepts(NO_PROGRAM + "\n" + NO_PROGRAM + "\n\n")


def test_the_grammar_sent_to_an_endpoint_is_the_capped_canonical_one(profile: Profile) -> None:
    """What goes over the wire to an OpenAI-compatible server: the automaton's language, cap included."""
    received: list[dict] = []

    class Handler(BaseHTTPRequestHandler):
        def do_POST(self) -> None:
            received.append(json.loads(self.rfile.read(int(self.headers["Content-Length"]))))
            reply = json.dumps({"choices": [{"text": "perceive;\n\n", "finish_reason": "stop"}]}).encode()
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(reply)))
            self.end_headers()
            self.wfile.write(reply)

        def log_message(self, *args: object) -> None:
            """Quiet."""

    server = HTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        engine = HttpEngine(f"http://127.0.0.1:{server.server_port}")
        automaton = RslAutomaton(profile, objects=["cup"], max_statements=2, refusal=True)
        assert engine.generate("Task: look\nRSL:\n", automaton, 16).text == "perceive;\n\n"
    finally:
        server.shutdown()
        server.server_close()
    sent = gbnf.parse(received[0]["grammar"]).regex()
    assert sent.fullmatch("grasp cup;\nperceive;\n\n") and sent.fullmatch(NO_PROGRAM + "\n\n")
    assert not sent.fullmatch("perceive;\n" * 3 + "\n")
    assert not sent.fullmatch("grasp mug;\n\n")
