"""Where the model could have ended a program, and the earlier ending tried when the whole one fails a check."""

from __future__ import annotations

from agent.normalize import normalize_task
from agent.translate import Translator
from agent.translate.automaton import RslAutomaton
from agent.translate.clauses import Clause
from agent.translate.translator import ENDING_FLOOR, _ClauseState

SQUARE_SIDE = "forward 1;\nturnleft 1.5708;\n"


def _square_state(sides: int, ending_after: int, probability: float) -> _ClauseState:
    """A whole-task state whose program drives `sides` sides, with an ending the model weighed after `ending_after`."""
    state = _ClauseState(Clause(text=normalize_task("drive in a square with 1 meter sides")))
    state.program = SQUARE_SIDE * sides
    state.probabilities = tuple(0.9 for _ in range(10 * sides))
    statements = 2 * sides
    state.endings = tuple((count, 5 * count, probability if count == ending_after else ENDING_FLOOR / 10)
                          for count in range(1, statements))
    return state


def test_the_engine_reports_each_place_the_program_could_have_ended(translator: Translator) -> None:
    automaton = RslAutomaton(translator.profile)
    prompt = "Task: drive forward 1 m, then turn left 90 degrees, then drive forward 2 m\nRSL:\nforward 1;\n"
    generation = translator.engine.generate(prompt, automaton, 40)
    statements = generation.text.count(";")
    assert statements >= 1
    counts = [count for count, _chosen, _p in generation.endings]
    # An end is possible after every statement but the last (there the model did end, or hit the cap).
    assert set(range(1, statements)) <= set(counts)
    assert all(0.0 <= p <= 1.0 for _c, _i, p in generation.endings)
    chosen = [index for _c, index, _p in generation.endings]
    assert chosen == sorted(chosen) and all(0 <= i < len(generation.token_probabilities) for i in chosen)


def test_a_failed_check_takes_the_likely_earlier_ending_that_passes(translator: Translator) -> None:
    state = _square_state(sides=5, ending_after=8, probability=0.3)
    found = translator._shorter_ending(state, state.clause.text, None)
    assert found is not None
    program, plan, probabilities, _assessment = found
    assert program == SQUARE_SIDE * 4 and len(plan) == 8
    # The ending's own probability is part of the model's signal, so the plan is not more trusted than it.
    assert probabilities[-1] == 0.3 and len(probabilities) == 5 * 8 + 1


def test_an_ending_the_model_hardly_weighed_is_not_taken(translator: Translator) -> None:
    state = _square_state(sides=5, ending_after=8, probability=ENDING_FLOOR / 2)
    assert translator._shorter_ending(state, state.clause.text, None) is None


def test_an_earlier_ending_that_also_fails_the_checks_is_not_taken(translator: Translator) -> None:
    state = _square_state(sides=5, ending_after=4, probability=0.6)  # two sides of a square
    assert translator._shorter_ending(state, state.clause.text, None) is None
