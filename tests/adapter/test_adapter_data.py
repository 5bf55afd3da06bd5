"""The training-data generator: coverage, correctness and reproducibility, from the profile."""

from __future__ import annotations

import re

import pytest

from agent.adapter.data import (
    NO_PROGRAM,
    Generator,
    Pair,
    asr_noise,
    check_programs,
    classify,
    convention_amounts,
    generate,
    number_words,
)
from agent.adapter.prompt import adapter_prompt, training_text
from agent.normalize import normalize_task
from rsl.compiler import compile_program
from rsl.profile import Profile, load_profile, parse_profile


@pytest.fixture(scope="module")
def pairs(profile: Profile):
    return generate(profile, 1500, seed=7)


def test_every_program_compiles_and_is_canonical(pairs, profile: Profile) -> None:
    for pair in pairs:
        if pair.group == "refuse":
            assert pair.program == NO_PROGRAM + "\n"
            continue
        result = compile_program(pair.program, profile)
        assert result.ok, (pair, result.diagnostics)
        assert result.plan is not None and result.plan.to_rsl() == pair.program


def test_every_skill_and_group_is_covered(pairs, profile: Profile) -> None:
    used = {line.split()[0].rstrip(";") for pair in pairs for line in pair.program.splitlines()
            if pair.group != "refuse"}
    assert used == set(profile.keywords)
    assert {p.group for p in pairs} == {"simple", "ambiguous", "multi-step", "complex", "correction",
                                        "negation", "activity", "repetition", "refuse"}


def test_training_input_is_the_normalized_task(pairs) -> None:
    assert all(pair.normalized == normalize_task(pair.task) for pair in pairs)
    assert len({pair.normalized for pair in pairs}) == len(pairs)


def test_same_seed_same_data_other_seed_other_data(profile: Profile) -> None:
    assert generate(profile, 200, seed=3) == generate(profile, 200, seed=3)
    assert generate(profile, 200, seed=3) != generate(profile, 200, seed=4)


def test_units_number_words_and_repetition_appear(pairs) -> None:
    tasks = " ".join(p.task.lower() for p in pairs)
    for phrase in ("degrees", "centimeters", "half a met", "times", "square", "triangle", "full circle",
                   " it", "look around"):
        assert phrase in tasks, phrase
    assert re.search(r"\b(two|three|four|five|ten) (meters|metres|meter|m)\b", tasks)


def test_vague_amounts_follow_the_profile_conventions(profile: Profile) -> None:
    vague, defaults = convention_amounts(profile.conventions)
    assert {(a.phrase, a.value) for a in vague} >= {("a little", 0.2), ("a long distance", 5.0)}
    assert {(a.unit, a.value) for a in defaults} >= {("m", 1.0), ("rad", 1.5708)}
    found = {p.normalized: p.program for p in generate(profile, 3000, seed=11)}
    little = [prog for text, prog in found.items() if re.fullmatch(r"(move|go|drive) forward a little", text)]
    assert little and all(prog == "forward 0.2;\n" for prog in little)
    around = [prog for text, prog in found.items() if text == "turn around"]
    assert around == ["turnleft 3.1416;\n"]


def test_asr_noise_is_lowercase_without_punctuation_and_uses_homophones() -> None:
    import random

    rng = random.Random(1)
    noisy = {asr_noise("Move forward two meters, then turn left.", rng) for _ in range(60)}
    assert all(text == text.lower() and "," not in text and not text.endswith(".") for text in noisy)
    assert any(" to meters" in text or " too meters" in text for text in noisy)
    assert any(text.split()[0] in ("uh", "um", "uhm", "er", "okay", "please", "hmm") for text in noisy)


def test_a_new_robot_gets_its_own_data_without_code_changes() -> None:
    text = """
[robot]
name = "crawler"
[[skills]]
keyword = "crawl"
description = "Crawl straight ahead by a distance."
params = [{ name = "distance", kind = "number", unit = "m", min = 0.1, max = 3.0 }]
[[skills]]
keyword = "pivotleft"
description = "Turn on the spot to the left by an angle."
params = [{ name = "angle", kind = "number", unit = "rad", min = 0.01, max = 3.2 }]
[[skills]]
keyword = "beep"
description = "Make a sound."
params = []
[[skills]]
keyword = "paint"
description = "Paint a mark of a given width."
params = [{ name = "width", kind = "number", unit = "m", min = 0.05, max = 0.5 }, { name = "colour", kind = "object" }]
"""
    crawler = parse_profile(text)
    assert [classify(s).kind for s in crawler.skills] == ["drive", "turn", "perceive", "other"]
    data = generate(crawler, 300, seed=0)
    keywords = {line.split()[0].rstrip(";") for p in data for line in p.program.splitlines()
                if p.group != "refuse"}
    assert keywords == {"crawl", "pivotleft", "beep", "paint"}
    # Ranges come from the profile: the crawler never crawls more than 3 m.
    assert all(float(line.split()[1].rstrip(";")) <= 3.0
               for p in data for line in p.program.splitlines() if line.startswith("crawl "))


def test_a_program_that_does_not_compile_is_refused(profile: Profile) -> None:
    bad = Pair(task="drive 99 meters", normalized="drive 99 m", program="forward 99;\n", group="simple",
               prompt=adapter_prompt("drive 99 m", profile))
    with pytest.raises(ValueError, match="does not compile"):
        check_programs([*generate(profile, 5, seed=0), bad], profile)


def test_number_words() -> None:
    assert [number_words(n) for n in (0, 7, 20, 45, 100, 135)] == [
        "zero", "seven", "twenty", "forty five", "one hundred", "one hundred and thirty five"]
    assert all(normalize_task(f"{number_words(n)} meters") == f"{n} m" for n in range(1, 200, 7))


def test_prompt_and_completion_match_the_grammar_format(profile: Profile) -> None:
    prompt, completion = training_text(adapter_prompt("move  forward 2 m", profile), "forward 2;\n")
    assert prompt == "Task: move forward 2 m\nRSL:\n"
    assert completion == "forward 2;\n\n"


def test_the_prompt_notes_the_conventions_the_task_uses(profile: Profile) -> None:
    look_around = next(c for c in profile.conventions if c.phrase == "look around")
    little = next(c for c in profile.conventions if c.phrase == "a little")
    prompt = adapter_prompt("look around, then move forward a little", profile)
    # A whole command is noted with its program, an amount with its meaning.
    assert f"Note: look around = {' '.join(look_around.program.split())}\n" in prompt
    assert f"Note: a little = {little.meaning}\n" in prompt
    assert prompt.endswith("RSL:\n")
    # Only phrases the task uses, as whole words.
    assert "Note" not in adapter_prompt("look around2 the corner", profile)
    # "a full circle" is already a number once normalized: no note repeats it.
    assert "Note" not in adapter_prompt(normalize_task("spin in a full circle"), profile)


def test_training_prompts_carry_the_notes(profile: Profile) -> None:
    pairs = generate(profile, 400, seed=3)
    noted = [p for p in pairs if "look around" in p.normalized]
    assert noted and all(p.prompt == adapter_prompt(p.normalized, profile) for p in pairs)
    assert all("Note: look around = " in p.prompt for p in noted)
    assert load_profile().skill("forward") is not None


def test_words_that_are_no_task_have_no_program(pairs) -> None:
    refused = [p for p in pairs if p.group == "refuse"]
    assert len(refused) > len(pairs) // 20
    assert all(p.program == NO_PROGRAM + "\n" for p in refused)
    assert NO_PROGRAM not in {p.program.strip() for p in pairs if p.group != "refuse"}


def test_a_self_correction_keeps_only_what_was_settled_on(profile: Profile) -> None:
    generator = Generator(profile, seed=5)
    for _ in range(200):
        clause = generator.correction()
        numbers = re.findall(r"\d+(?:\.\d+)?", normalize_task(clause.text))
        assert len(clause.commands) == 1
        if numbers:
            # The program carries the last amount said, as the normalizer converted it.
            assert clause.commands[0].number() == float(numbers[-1]), clause


def test_an_activity_convention_is_varied_in_its_object(profile: Profile) -> None:
    generator = Generator(profile, seed=2)
    seen = set()
    for _ in range(60):
        clause = generator.activity()
        assert clause is not None and clause.obj is not None
        assert [c.skill for c in clause.commands] == ["approach", "grasp", "goto"]
        assert all(c.args[0].name == clause.obj for c in clause.commands[:2])  # type: ignore[union-attr]
        assert clause.obj.replace("_", " ") in clause.text
        seen.add(clause.obj)
    assert len(seen) > 10


def test_a_negated_skill_is_not_in_the_program(profile: Profile) -> None:
    generator = Generator(profile, seed=3)
    for _ in range(200):
        clause = generator.negated()
        if clause.text.startswith("don't move, just "):
            assert all(c.skill not in ("forward", "backward", "approach", "goto") for c in clause.commands)


def test_an_object_convention_is_noted_by_its_meaning(profile: Profile) -> None:
    prompt = adapter_prompt(normalize_task("go get the mug"), profile)
    assert "Note: go get = approach the object, grasp it" in prompt
    assert "cup" not in prompt
