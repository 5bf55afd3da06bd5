"""The translation loop with the real embedded model: contract, grammar, repair, cap, fallback."""

from __future__ import annotations

import dataclasses

import pytest

from agent.translate import ModelNotFoundError, Translator
from agent.translate.automaton import END, START, RslAutomaton
from agent.translate.engine import TokenMasks
from rsl.compiler import compile_program
from rsl.diagnostics import Code
from rsl.profile import Profile

CONTRACT_KEYS = {"task", "program", "verified", "passes", "attempts", "plan", "model", "timings_ms",
                 "explanation", "confidence", "doubts", "confirm", "refused"}


def _variant(translator: Translator, **changes: object) -> Translator:
    """The same loaded model with other options, so no test loads it twice."""
    options = dataclasses.replace(translator.options, **changes)  # type: ignore[arg-type]
    return Translator(translator.profile, translator.engine, translator.model_name, options)


def test_result_follows_the_json_contract(translator: Translator, profile: Profile) -> None:
    result = translator.translate("move forward two meters, then grasp the cup", known_objects=["cup"])
    data = result.to_json_dict()
    assert set(data) == CONTRACT_KEYS
    assert set(data["timings_ms"]) == {"prompt", "generate", "compile", "checks", "total"}
    assert data["passes"] == len(data["attempts"]) >= 1
    assert all(set(a) == {"program", "diagnostics"} for a in data["attempts"])
    assert data["program"] == data["attempts"][-1]["program"]
    if result.verified:
        assert result.plan is not None and compile_program(result.program, profile, ["cup"]).ok
        assert [c["rsl"] for c in data["plan"]] == result.program.splitlines()
    else:
        assert data["plan"] == []


@pytest.mark.parametrize("task", ["turn left ninety degrees", "uh go to 1, -2 then look around",
                                  "approach the red box and take it", "spin in a full circle"])
def test_grammar_makes_syntax_errors_impossible(translator: Translator, task: str) -> None:
    result = translator.translate(task)
    for attempt in result.attempts:
        assert all(d.code.is_semantic for d in attempt.diagnostics), attempt
    assert result.verified, result.attempts


def test_loop_repairs_a_misheard_object(translator: Translator) -> None:
    """The task names a cop, the robot knows a cup: the compiler's E104 drives a second pass."""
    seen = []
    result = translator.translate("grasp the cop", known_objects=["cup", "table"], on_attempt=seen.append)
    assert len(seen) == result.passes == 2
    assert [d.code for d in result.attempts[0].diagnostics] == [Code.UNKNOWN_OBJECT]
    assert result.verified and result.plan is not None
    assert {c.object() for c in result.plan if c.skill in ("grasp", "approach")} == {"cup"}


def test_another_object_is_refused_not_swapped(translator: Translator) -> None:
    """A mug is not a misheard cup: grasping the cup instead would do what nobody asked."""
    result = translator.translate("grasp the mug", known_objects=["cup", "table"])
    assert result.passes == 1 and not result.verified and result.plan is None
    [diagnostic] = result.attempts[-1].diagnostics
    assert diagnostic.code is Code.UNKNOWN_OBJECT and diagnostic.token == "mug"
    assert "`cup`" in diagnostic.message


def test_likely_meant_objects() -> None:
    from agent.translate.translator import _likely_meant

    known = ["cup", "red_cup", "table", "bottle"]
    assert _likely_meant(["cop"], known) == ("cup",)
    assert _likely_meant(["bottel"], known) == ("bottle",)
    assert _likely_meant(["blue_cup"], known) == ("cup", "red_cup")
    assert _likely_meant(["mug"], known) == ()


def test_pass_cap_is_honoured(translator: Translator) -> None:
    capped = _variant(translator, max_passes=1)
    result = capped.translate("grasp the mug", known_objects=["cup"])
    assert result.passes == 1 and len(result.attempts) == 1
    assert not result.verified and result.plan is None


def test_no_grammar_mode_still_compiles_every_candidate(translator: Translator) -> None:
    free = _variant(translator, grammar=False)
    result = free.translate("turn left 90 degrees")
    assert 1 <= result.passes <= 3
    for attempt in result.attempts:
        assert attempt.program or attempt.diagnostics
    assert result.verified == (not result.attempts[-1].diagnostics)


def test_token_masks_only_allow_tokens_that_stay_in_the_language(translator: Translator,
                                                                 profile: Profile) -> None:
    automaton = RslAutomaton(profile, objects=["cup"])
    masks = TokenMasks(automaton, translator.engine.vocabulary)  # type: ignore[attr-defined]
    pieces = translator.engine.vocabulary.pieces  # type: ignore[attr-defined]
    for prefix in ["", "forward ", "forward 1", "grasp ", "goto -", "perceive;", "perceive;\n"]:
        state = automaton.walk(START, prefix)
        ids, states = masks.at(state)
        assert len(ids) > 0
        for token, after in zip(ids.tolist()[:400], states[:400], strict=True):
            assert automaton.walk(state, pieces[token].decode("ascii")) == after
    assert END in masks.at(automaton.walk(START, "perceive;\n"))[1]


def test_prompt_prefix_is_reused_across_requests(translator: Translator) -> None:
    engine = translator.engine
    first = engine.generate(translator.prompt_for("turn left 1 rad"), None, 4)
    second = engine.generate(translator.prompt_for("go back 2 m"), None, 4)
    assert first.prompt_tokens > 200
    assert second.reused_tokens >= len(translator._system) // 8  # the whole system text, at least


def test_empty_task_is_not_verified(translator: Translator) -> None:
    result = translator.translate("uh um")
    assert not result.verified and result.passes == 0 and result.program == ""


def test_missing_model_gives_a_clear_error(profile: Profile, tmp_path) -> None:
    with pytest.raises(ModelNotFoundError, match="does not exist"):
        Translator.load(profile, model=str(tmp_path / "missing.gguf"))
    with pytest.raises(ModelNotFoundError, match="adapter"):
        Translator.load(profile, adapter=str(tmp_path / "missing-adapter.gguf"))


def test_the_shipped_adapter_is_the_default_and_stays_verified(profile: Profile) -> None:
    from agent.adapter.prompt import DEFAULT_ADAPTER

    adapted = Translator.load(profile)
    try:
        assert adapted.options.adapter_prompt and adapted.options.shots == 0
        assert not adapted.options.narrow_skills and adapted.options.narrow
        assert adapted.model_name.endswith("+" + DEFAULT_ADAPTER.name)
        result = adapted.translate("pick up the cup", known_objects=["cup"])
        assert result.verified and result.program == "grasp cup;\n"
        # A thing named in two words is named whole, not by the one word a model trained on one-word
        # names would keep.
        assert adapted.translate("pick up the water bottle please").program == "grasp water_bottle;\n"
        # The convention's program comes from the profile through the prompt's note.
        result = adapted.translate("look around")
        assert result.verified
        look_around = next(c for c in profile.conventions if c.phrase == "look around")
        expected = compile_program(look_around.program, profile).plan
        assert result.plan is not None and expected is not None
        assert result.plan.to_rsl() == expected.to_rsl()
        # Words that are no task are refused, not forced into a program by the grammar.
        chat = adapted.translate("what time is it")
        assert not chat.verified and chat.plan is None and chat.passes == 1
        assert [d.code for d in chat.attempts[0].diagnostics][:1] == [Code.NOT_A_TASK]
        assert "'what time is it' does not read as a task" in chat.attempts[0].diagnostics[0].message
    finally:
        adapted.close()


def test_no_adapter_for_another_robot_or_when_turned_off() -> None:
    from agent.translate.translator import _resolve_adapter
    from rsl.profile import default_profile_path, parse_profile

    text = default_profile_path().read_text("utf-8")
    other_robot = parse_profile(text.replace('name = "default"', 'name = "other"'))
    default = parse_profile(text)
    assert _resolve_adapter(None, default_model=True, profile=default) is not None
    assert _resolve_adapter(None, default_model=True, profile=other_robot) is None
    assert _resolve_adapter(None, default_model=False, profile=default) is None
    assert _resolve_adapter("none", default_model=True, profile=default) is None
    # Asked for by name, it loads for any profile.
    assert _resolve_adapter("default", default_model=True, profile=other_robot) is not None


def test_an_adapter_for_another_prompt_format_is_refused(profile: Profile, tmp_path) -> None:
    import shutil

    from agent.adapter.card import card_path, read_card
    from agent.adapter.prompt import DEFAULT_ADAPTER, PROMPT_VERSION

    adapter = tmp_path / "old.gguf"
    shutil.copyfile(DEFAULT_ADAPTER, adapter)
    old = dataclasses.replace(read_card(card_path(DEFAULT_ADAPTER)), prompt_version=PROMPT_VERSION - 1)
    old.write(card_path(adapter))
    with pytest.raises(ModelNotFoundError, match="prompt format"):
        Translator.load(profile, adapter=str(adapter))


def test_a_clause_reads_as_a_task_when_the_model_would_start_rsl_and_is_sure(profile: Profile) -> None:
    from agent.translate.engine import Generation
    from agent.translate.translator import GUESSING_BELOW, _sure_it_is_a_task, task_reading

    def first(piece: str, probability: float | None) -> Generation:
        return Generation(text="", prompt_tokens=1, reused_tokens=0, generated_tokens=0, prompt_ms=0.0,
                          generate_ms=0.0, finished=True, first_piece=piece, first_probability=probability)

    def reads_as_task(generation: Generation) -> bool:
        return _sure_it_is_a_task(task_reading(generation, profile))

    assert reads_as_task(first("forward", 0.99))
    assert reads_as_task(first("look", 0.9))  # a piece of `lookleft`
    assert not reads_as_task(first("sing", 0.99))  # the model wants to write something else
    assert not reads_as_task(first("turn", GUESSING_BELOW / 2))  # a guess
    assert not reads_as_task(first("", 0.99))  # it would end at once
    assert reads_as_task(first("", None))  # an engine that cannot tell refuses nothing
    assert task_reading(first("turn", 0.6), profile) == 0.6
    assert task_reading(first("sing", 0.99), profile) == 0.0
    assert task_reading(first("", None), profile) is None
