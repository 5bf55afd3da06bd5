"""The profile is the one source of truth: a new skill needs no code."""

from __future__ import annotations

import re

import pytest

from rsl.codegen import to_python
from rsl.compiler import compile_program
from rsl.describe import language_description, markdown_reference
from rsl.grammar import to_gbnf
from rsl.profile import ProfileError, default_profile_path, load_profile, parse_profile
from tests.rsl import gbnf

WAVE = """
[[skills]]
keyword = "wave"
description = "Wave the gripper a number of times."
example = "wave 3;"
aliases = ["greet"]
params = [{ name = "times", kind = "number", unit = "waves", min = 1, max = 5 }]
"""


@pytest.fixture(scope="module")
def waving():
    return parse_profile(default_profile_path().read_text() + WAVE, source="waving.toml")


def test_default_profile_declares_the_twelve_skills(profile):
    assert profile.keywords == ("forward", "backward", "turnleft", "turnright", "lookup", "lookdown",
                                "lookleft", "lookright", "perceive", "approach", "grasp", "goto")
    assert [len(s.params) for s in profile.skills] == [1] * 8 + [0, 1, 1, 2]


def test_an_extra_skill_parses_compiles_and_appears_everywhere(waving, profile):
    result = compile_program("forward 1;\nwave 3;\n", waving)
    assert result.ok and result.plan.commands[1].skill == "wave"
    assert result.plan.commands[1].number() == 3.0
    assert not compile_program("wave 3;", profile).ok
    assert [d.code.code for d in compile_program("wave 9;", waving).diagnostics] == ["E101"]
    assert "did you mean `wave`" in compile_program("greet 2;", waving).diagnostics[0].message

    grammar = to_gbnf(waving)
    assert '"wave " number-1 ";"' in grammar
    assert gbnf.parse(grammar).regex().fullmatch("wave 3;\n\n")
    assert "`wave TIMES;` Wave the gripper" in language_description(waving)
    assert "`wave TIMES;`" in markdown_reference(waving)
    assert "robot.wave(3.0, cancel=cancel)" in to_python(result.plan)


@pytest.mark.parametrize(("patch", "complaint"), [
    ('keyword = "Forward"', "must be a lowercase identifier"),
    ('keyword = "import"', "not a Python keyword"),
    ('kind = "colour"', "must be \"number\" or \"object\""),
])
def test_broken_profiles_are_rejected_with_the_reason(patch, complaint):
    text = default_profile_path().read_text()
    key = patch.split(" = ")[0]
    original = 'keyword = "forward"' if key == "keyword" else 'kind = "number"'
    with pytest.raises(ProfileError, match=complaint):
        parse_profile(text.replace(original, patch, 1), source="broken.toml")


def test_what_the_robot_is_called_comes_from_the_profile_and_leaves_the_digest(profile):
    assert profile.called == ("robot",)
    text = default_profile_path().read_text()
    named = parse_profile(text.replace('called = ["robot"]', 'called = ["robot", "robbie"]'), source="named.toml")
    assert named.called == ("robot", "robbie")
    assert named.digest == profile.digest, "what the robot is called is how it is spoken to, not its language"
    with pytest.raises(ProfileError, match=r"\[robot\] called must be a list of lower-case words"):
        parse_profile(text.replace('called = ["robot"]', 'called = "Robbie"'), source="broken.toml")


def test_other_words_for_a_convention_come_from_the_profile_and_leave_the_digest(profile):
    little = next(c for c in profile.conventions if c.phrase == "a little")
    assert "slightly" in little.also
    text = default_profile_path().read_text()
    without = parse_profile(re.sub(r"\nalso = \[[^\]]*\]", "", text), source="without.toml")
    assert all(not c.also for c in without.conventions)
    assert without.digest == profile.digest, "other words are how a phrase is heard, not what an adapter learned"
    with pytest.raises(ProfileError, match="`also` must be a list of lower-case words"):
        parse_profile(text.replace('also = ["a long way"', 'also = ["A long way"'), source="broken.toml")
    with pytest.raises(ProfileError, match="`also` word 'a bit further' is another convention's phrase"):
        parse_profile(text.replace('also = ["a long way"', 'also = ["a bit further", "a long way"'),
                      source="broken.toml")


def test_missing_profile_file_is_a_clear_error(tmp_path):
    with pytest.raises(ProfileError, match="cannot read robot profile"):
        load_profile(tmp_path / "absent.toml")


def test_not_toml_is_a_clear_error():
    with pytest.raises(ProfileError, match="not valid TOML"):
        parse_profile("[[skills]\n", source="bad.toml")


def test_words_in_another_language_come_from_the_profile_and_leave_the_digest(profile):
    forward = profile.skill("forward")
    assert forward is not None and forward.words_in("ko") == ("앞으로", "전진")
    assert forward.words_in("en") == ()
    text = default_profile_path().read_text()
    without = parse_profile(text.replace('words = { ko = ["앞으로", "전진"] }\n', ""), source="plain.toml")
    assert without.digest == profile.digest, "words are how a skill is heard, not what an adapter learned"
    with pytest.raises(ProfileError, match="`words` must map a language code"):
        parse_profile(text.replace('words = { ko = ["앞으로", "전진"] }', 'words = { ko = "앞으로" }'),
                      source="broken.toml")


@pytest.mark.parametrize(("patch", "replacement", "message"), [
    ("max_linear_speed = 0.5", 'max_linear_speed = "fast"',
     "my.toml: motion.max_linear_speed must be a number, not 'fast'"),
    ("max_statements = 64", 'max_statements = "many"',
     "my.toml: limits.max_statements must be a whole number, not 'many'"),
    ("max_statements = 64", "max_statements = 0", "my.toml: limits.max_statements = 0 is below the minimum 1"),
    ("reach = 0.8", "reach = 0.8\nreech = 1",
     "my.toml: unknown setting motion.reech\n  = help: the settings here are motion.max_linear_speed, "
     "motion.max_angular_speed, motion.max_linear_accel, motion.max_angular_accel, motion.max_head_speed, "
     "motion.reach, motion.standoff, motion.timeout_margin, motion.width; see docs/skills.md"),
])
def test_profile_settings_are_checked_like_every_other_setting(patch, replacement, message):
    text = default_profile_path().read_text()
    assert patch in text
    with pytest.raises(ProfileError) as caught:
        parse_profile(text.replace(patch, replacement, 1), source="my.toml")
    assert str(caught.value) == message


@pytest.mark.parametrize(("table", "complaint"), [
    ('part = "tail"\nphrases = ["tail back"]',
     r"part 'tail' is not a part the robot's description names \(its parts: base, gripper, head\)"),
    # The camera is the head's: the head's skills move it, so only "head" would ever be put back.
    ('part = "camera"\nphrases = ["camera back"]', "part 'camera' is not a part"),
    ('part = "head"\nphrases = []', "needs `part`"),
    ('phrases = ["head back"]', "needs `part`"),
])
def test_a_part_put_back_must_be_a_part_of_the_robot_with_its_words(table, complaint):
    _refused_with("back", table, complaint)


@pytest.mark.parametrize(("table", "complaint"), [
    ('toward = "+z"\nphrases = ["up"]',
     r"\[\[frame\]\] #\d+: toward '\+z' must be \+ or - and an axis of the workspace \(x, y\)"),
    ('toward = "x"\nphrases = ["ahead"]', "toward 'x' must be"),
    ('toward = "+x"\nphrases = []', "needs `toward`"),
])
def test_a_frame_way_needs_a_signed_axis_of_the_workspace_and_its_words(table, complaint):
    _refused_with("frame", table, complaint)


def test_the_default_robot_reads_points_from_its_start_without_touching_the_language(profile):
    ways = {(w.axis, w.sign): w.phrases for w in profile.frame}
    assert "ahead" in ways[("x", 1)] and "behind" in ways[("x", -1)]
    assert "to your left" in ways[("y", 1)] and "to your right" in ways[("y", -1)]
    text = default_profile_path().read_text()
    without = re.sub(r"\[\[frame\]\]\ntoward = .*\nphrases = .*\n", "", text)
    assert without != text and parse_profile(without).digest == profile.digest


@pytest.mark.parametrize(("table", "complaint"), [
    ('what = "water plants"\nphrases = []', r"\[\[cannot\]\] #\d+ needs `what` \(a sentence\)"),
    ('phrases = ["water the plants"]', r"needs `what`"),
    ('what = "water plants"\nphrases = ["Forward "]', "phrase 'forward' is a word for the skill `forward`"),
])
def test_what_a_robot_cannot_do_needs_its_sentence_and_words_that_are_no_skill(table, complaint):
    _refused_with("cannot", table, complaint)


def _refused_with(name, table, complaint):
    """The default profile with one more `[[name]]` table is refused with `complaint`."""
    text = default_profile_path().read_text() + f"\n[[{name}]]\n" + table + "\n"
    with pytest.raises(ProfileError, match=complaint):
        parse_profile(text, source="broken.toml")


def test_the_default_robot_puts_its_head_back(profile):
    assert [b.part for b in profile.back] == ["head"]
    assert "look straight ahead again" in profile.back[0].phrases
