"""The `// no program` line: the grammar offers it only when asked, and writing it refuses the clause."""

from __future__ import annotations

import dataclasses

import pytest

from agent.normalize import normalize_task
from agent.translate import Translator
from agent.translate.automaton import END, START, RslAutomaton
from agent.translate.engine import CancelFlag, Fork, Generation, TokenMasks
from rsl.diagnostics import Code
from rsl.grammar import to_gbnf
from rsl.profile import Profile
from rsl.syntax import NO_PROGRAM
from tests.rsl import gbnf

REFUSAL = NO_PROGRAM + "\n\n"


def test_refusal_line_is_offered_only_when_asked(profile: Profile) -> None:
    with_refusal = RslAutomaton(profile, refusal=True)
    assert with_refusal.accepts(REFUSAL)
    assert with_refusal.accepts("forward 2;\n\n")
    for bad in [NO_PROGRAM + "\n", NO_PROGRAM + "\nforward 2;\n\n", "forward 2;\n" + REFUSAL, "// no\n\n"]:
        assert not with_refusal.accepts(bad), bad
    assert not RslAutomaton(profile).accepts(REFUSAL)


def test_every_gbnf_writer_offers_the_refusal_line_only_when_asked(profile: Profile) -> None:
    for with_refusal, without in [(to_gbnf(profile, refusal=True), to_gbnf(profile)),
                                  (RslAutomaton(profile, refusal=True).to_gbnf(), RslAutomaton(profile).to_gbnf())]:
        assert gbnf.parse(with_refusal).regex().fullmatch(REFUSAL)
        assert gbnf.parse(with_refusal).regex().fullmatch("forward 2;\n\n")
        assert not gbnf.parse(with_refusal).regex().fullmatch(NO_PROGRAM + "\nforward 2;\n\n")
        assert not gbnf.parse(without).regex().fullmatch(REFUSAL)


def test_the_real_vocabulary_can_spell_the_refusal_token_by_token(translator: Translator, profile: Profile) -> None:
    """Every token of the model's own spelling of the line is in the mask at its step."""
    automaton = RslAutomaton(profile, refusal=True)
    masks = TokenMasks(automaton, translator.engine.vocabulary)  # type: ignore[attr-defined]
    llm = translator.engine.llm  # type: ignore[attr-defined]
    state = START
    for token in llm.tokenize(REFUSAL.encode(), add_bos=False, special=False):
        ids, states = masks.at(state)
        assert token in ids.tolist(), (state, llm.detokenize([token]))
        state = states[ids.tolist().index(token)]
    assert state == END
    plain = TokenMasks(RslAutomaton(profile), translator.engine.vocabulary)  # type: ignore[attr-defined]
    assert llm.tokenize(b"//", add_bos=False, special=False)[0] not in plain.at(START)[0].tolist()


class _PrimedEngine:
    """The real engine, with a prompt that shows the model writing the refusal line for small talk."""

    chat_template = ""

    def __init__(self, engine: object) -> None:
        self.engine = engine
        self.prompts: list[str] = []

    def generate(self, prompt: str, automaton: RslAutomaton | None, max_tokens: int,
                 cancel: CancelFlag | None = None, fork: Fork | None = None) -> Generation:
        self.prompts.append(prompt)
        shots = "".join(f"Task: {t}\nRSL:\n{REFUSAL}" for t in ("tell me a joke", "hello there", "how are you"))
        return self.engine.generate(shots + "Task: what time is it\nRSL:\n", automaton, max_tokens,  # type: ignore[attr-defined]
                                    fork=fork)

    def close(self) -> None:
        """The wrapped engine belongs to the session fixture."""


@pytest.mark.parametrize("grammar", [True, False])
def test_writing_the_refusal_line_refuses_the_task_without_repair(translator: Translator, grammar: bool) -> None:
    engine = _PrimedEngine(translator.engine)
    options = dataclasses.replace(translator.options, refusal=True, grammar=grammar, split_clauses=False)
    refusing = Translator(translator.profile, engine, translator.model_name, options)  # type: ignore[arg-type]
    result = refusing.translate("what time is it")
    assert result.attempts[0].program == NO_PROGRAM + "\n"
    assert not result.verified and result.plan is None and result.passes == len(engine.prompts) == 1
    assert [d.code for d in result.attempts[0].diagnostics] == [Code.NOT_A_TASK]
    assert "no program" in result.attempts[0].diagnostics[0].message


def test_without_the_option_the_grammar_forces_a_program(translator: Translator) -> None:
    engine = _PrimedEngine(translator.engine)
    options = dataclasses.replace(translator.options, split_clauses=False)
    plain = Translator(translator.profile, engine, translator.model_name, options)  # type: ignore[arg-type]
    result = plain.translate("what time is it")
    assert NO_PROGRAM not in result.program


class _FirstReadingEngine:
    """The real engine, reporting the model's free first choice as `forward`, `probability` sure: the
    first-token reading a task gets varies with the CPU's arithmetic, so the test sets it."""

    def __init__(self, engine: object, probability: float) -> None:
        self.engine = engine
        self.probability = probability
        self.chat_template = getattr(engine, "chat_template", "")

    def generate(self, prompt: str, automaton: RslAutomaton | None, max_tokens: int,
                 cancel: CancelFlag | None = None, fork: Fork | None = None) -> Generation:
        generation = self.engine.generate(prompt, automaton, max_tokens, cancel, fork=fork)  # type: ignore[attr-defined]
        return dataclasses.replace(generation, first_piece="forward", first_probability=self.probability)

    def close(self) -> None:
        """The wrapped engine belongs to the module's fixture."""


def test_a_doubted_plan_the_model_guessed_at_is_refused_as_no_task(adapted: Translator) -> None:
    from agent.translate.translator import DOUBTED_GUESS_BELOW, GUESSING_BELOW

    task = "The water bottle is two meters in front of you."
    results = {}
    for probability in (GUESSING_BELOW + 0.01, DOUBTED_GUESS_BELOW - 0.01, DOUBTED_GUESS_BELOW + 0.01):
        engine = _FirstReadingEngine(adapted.engine, probability)
        results[probability] = Translator(adapted.profile, engine, adapted.model_name,  # type: ignore[arg-type]
                                          adapted.options).translate(task)
    sure = results[DOUBTED_GUESS_BELOW + 0.01]
    # The shipped adapter drives 2 m for it, and the meaning checks doubt that: asked, not refused.
    assert sure.verified and sure.confirm and sure.doubts, sure
    for probability in (GUESSING_BELOW + 0.01, DOUBTED_GUESS_BELOW - 0.01):
        guessed = results[probability]
        assert not guessed.verified and guessed.plan is None and guessed.refused and guessed.passes == 1
        (diagnostic,) = guessed.attempts[-1].diagnostics
        assert diagnostic.code is Code.NOT_A_TASK
        assert f"the model was {probability:.0%} sure it was one" in diagnostic.message
        assert sure.doubts[0] in diagnostic.message


@pytest.mark.parametrize(("task", "reason"), [
    ("If I told you to turn left, would you?", "you told of an order, imagined one or planned one for later"),
    ("Turn left... actually, never mind.", 'you called it off ("never mind")'),
])
def test_words_that_ask_for_nothing_now_are_refused_however_sure_the_model_is(adapted: Translator, task: str,
                                                                              reason: str) -> None:
    """A question about such a plan would put a motion to someone who never asked for one, so it is refused
    with the check's reason, even where the model is sure the words are a task."""
    engine = _FirstReadingEngine(adapted.engine, 0.99)
    result = Translator(adapted.profile, engine, adapted.model_name,  # type: ignore[arg-type]
                        adapted.options).translate(task)
    assert not result.verified and result.plan is None and result.refused and result.passes == 1, result
    (diagnostic,) = result.attempts[-1].diagnostics
    assert diagnostic.code is Code.NOT_A_TASK and reason in diagnostic.message


@pytest.mark.parametrize(("task", "phrase"), [
    ("Sweep the floor near the oven.", "sweep the floor"),
    ("put the cup on the table", "put the"),
    ("please switch on the kettle", "switch on"),
    ("could you turn off the lights", "turn off"),
    ("sing me a song", "sing"),
])
def test_what_the_default_robot_cannot_do_is_named_in_its_profile(task: str, phrase: str, profile: Profile) -> None:
    found = profile.inability(normalize_task(task))
    assert found is not None and found[1] == phrase


@pytest.mark.parametrize("task", [
    "go close to the table", "grab the clean cup", "drive to the elevator", "bring me my phone", "turn on the spot",
    "go to the charger", "fetch the mop", "look at the open door", "bring me the vacuum",
    "sweep the room with your camera",
])
def test_a_task_near_those_words_is_not_taken_for_one(task: str, profile: Profile) -> None:
    assert profile.inability(normalize_task(task)) is None


def test_a_request_the_default_robot_cannot_carry_out_is_refused_with_the_reason(adapted: Translator) -> None:
    # The shipped adapter had driven up to the oven.
    result = adapted.translate("Sweep the floor near the oven.")
    assert not result.verified and result.plan is None and result.passes == 0 and result.refused
    [diagnostic] = result.attempts[-1].diagnostics
    assert diagnostic.code is Code.NOT_A_TASK
    assert "asks the default robot to sweep the floor, and it cannot clean" in diagnostic.message
