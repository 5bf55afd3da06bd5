"""Bindings in the profile: validated when it loads, shown in the docs, and the only thing
below the profile that says what a skill does."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from agent.executor import step_timeout
from agent.translate.prompt import system_text
from rsl.compiler import compile_program
from rsl.describe import language_description, markdown_reference
from rsl.profile import Primitive, ProfileError, RosBinding, default_profile_path, load_profile, parse_profile
from tests.bindings.skills import extended_profile, profile_text
from tests.sim.renamed import FETCH_AND_RETURN, RENAMED, renamed_profile_text

REPO = Path(__file__).resolve().parents[2]
NRTRANS = [sys.executable, "-m", "agent.cli"]


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*NRTRANS, *args], cwd=REPO, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(REPO)})


def test_the_default_profile_binds_every_skill_to_a_primitive(profile) -> None:
    bound = {s.keyword: s.binding for s in profile.skills}
    assert all(isinstance(b, Primitive) for b in bound.values())
    assert bound["backward"] == Primitive("drive", -1.0) and bound["turnleft"] == Primitive("turn", 1.0)
    assert bound["lookdown"] == Primitive("tilt", -1.0) and bound["goto"] == Primitive("navigate")


def test_ros_bindings_load_with_their_names_and_values() -> None:
    profile = extended_profile()
    assert profile.skill("wave").binding == RosBinding(
        kind="joint_trajectory", name="/arm_controller/joint_trajectory", joints=("arm_shoulder_joint",),
        positions=("angle",), duration=0.5)
    assert profile.skill("dock").binding == RosBinding(kind="trigger", name="/dock")
    assert profile.skill("lights").binding == RosBinding(kind="topic", name="/lights/level",
                                                         message_type="std_msgs/msg/Float64",
                                                         fields=(("data", "level"),))


def test_new_skills_parse_and_appear_in_grammar_prompt_and_docs(tmp_path: Path) -> None:
    profile = extended_profile()
    result = compile_program("wave 0.8;\ndock;\nlights 0.5;\n", profile)
    assert result.ok, [d.brief() for d in result.diagnostics]
    path = tmp_path / "extended.toml"
    path.write_text(profile_text(), encoding="utf-8")
    grammar = cli("grammar", "--profile", str(path))
    assert grammar.returncode == 0, grammar.stderr
    assert '"wave "' in grammar.stdout and '"dock;"' in grammar.stdout and '"lights "' in grammar.stdout
    for text in (language_description(profile), system_text(profile)):
        assert "`wave ANGLE;` Wave" in text and "`dock;` Drive onto the charging dock." in text
    docs = cli("profile", "show", "--format", "markdown", "--profile", str(path))
    assert docs.returncode == 0, docs.stderr
    assert docs.stdout == markdown_reference(profile)
    assert ("| `wave ANGLE;` | Wave: swing the arm's shoulder to an angle and hold it there. | ANGLE in rad, "
            "from 0.1 to 1.5 | sends a trajectory_msgs/msg/JointTrajectory to arm_shoulder_joint on "
            "/arm_controller/joint_trajectory | `wave 0.8;` |") in docs.stdout
    assert "calls the std_srvs/srv/Trigger service /dock" in docs.stdout
    assert "publishes std_msgs/msg/Float64 on /lights/level" in docs.stdout
    shown = cli("profile", "show", "--format", "json", "--profile", str(path))
    bindings = {s["keyword"]: s["binding"] for s in json.loads(shown.stdout)["skills"]}
    assert bindings["dock"]["form"] == "ros" and bindings["dock"]["name"] == "/dock"
    assert bindings["backward"] == {"form": "primitive", "name": "drive", "sign": -1.0,
                                    "does": "primitive `drive`, sign -1"}


BASE = default_profile_path().read_text(encoding="utf-8")
FORWARD = 'binding = { primitive = "drive", sign = 1 }'


@pytest.mark.parametrize(("binding", "complaint"), [
    ('binding = { primitive = "fly" }', "primitive 'fly' is not one of drive, turn, pan, tilt, navigate"),
    ('binding = { primitive = "drive" }', "primitive `drive` needs sign = 1 or sign = -1 \\(-1 drives backward\\)"),
    ('binding = { primitive = "drive", sign = 2 }', "primitive `drive` needs sign = 1 or sign = -1"),
    ('binding = { primitive = "turn", sign = 1 }', "primitive `turn` takes number in rad; the skill "
                                                   "declares distance \\(number in m\\)"),
    ('binding = { primitive = "grasp_object" }', "primitive `grasp_object` takes object"),
    ('binding = { primitive = "drive", sign = 1, ros = "topic" }', "needs exactly one of `primitive`"),
    ('binding = { primitive = "drive", sign = 1, speed = 2 }',
     "has unknown key\\(s\\) speed; this form takes primitive, sign"),
    ('binding = "drive"', "must be a table"),
    ('binding = { ros = "action", topic = "/x" }', "ros 'action' is not one of topic, trigger, setbool"),
    ('binding = { ros = "trigger", service = "dock here" }', "`service` must be a ROS 2 name"),
    ('binding = { ros = "trigger", service = "/dock" }',
     "does not send the parameter\\(s\\) distance; a Trigger request carries none, so declare params = \\[\\]"),
    ('binding = { ros = "topic", topic = "/d", type = "Float64", fields = { data = "distance" } }',
     "`type` must be a message type such as"),
    ('binding = { ros = "topic", topic = "/d", type = "std_msgs/msg/Float64", fields = { data = "dist" } }',
     "field `data` takes the parameter 'dist', which the skill does not declare \\(its parameters: distance\\)"),
    ('binding = { ros = "joint_trajectory", topic = "/arm", joints = ["a", "b"], positions = ["distance"] }',
     "`positions` must give one position per joint \\(2\\)"),
    ('binding = { ros = "setbool", service = "/s", data = "yes" }', "`data` must be true or false"),
])
def test_a_bad_binding_is_a_profile_error_that_says_what_to_fix(binding: str, complaint: str) -> None:
    with pytest.raises(ProfileError, match=f"broken.toml: skill `forward`: binding {complaint}"):
        parse_profile(BASE.replace(FORWARD, binding, 1), source="broken.toml")


def test_navigate_needs_an_x_and_a_y_axis() -> None:
    text = BASE.replace('unit = "m", axis = "y"', 'unit = "m", axis = "x"', 1)
    with pytest.raises(ProfileError, match='`navigate` needs one parameter with axis = "x" and one with axis = "y"'):
        parse_profile(text, source="broken.toml")


def test_renamed_keywords_get_the_same_time_budgets(profile) -> None:
    renamed = parse_profile(renamed_profile_text(), source="renamed.toml")
    program = ("forward 1.5; backward 0.5; turnleft 1; turnright 2; lookup 0.3; lookdown 0.3; lookleft 1; "
               "lookright 1; perceive; approach table; grasp cup; goto 1, -2;")
    original = compile_program(program, profile).plan
    renamed_program = re.sub(r"\b(" + "|".join(RENAMED) + r")\b", lambda m: RENAMED[m.group(1)], program)
    again = compile_program(renamed_program, renamed).plan
    assert original is not None and again is not None
    assert [step_timeout(c, profile) for c in original] == [step_timeout(c, renamed) for c in again]
    assert compile_program(FETCH_AND_RETURN, renamed).ok


def test_no_module_below_the_profile_names_a_default_keyword(profile) -> None:
    """The executor, the robot interface and both backends read bindings, never keywords."""
    below = [REPO / "agent" / "executor.py", REPO / "agent" / "robot.py", REPO / "agent" / "sim" / "robot.py",
             *sorted((REPO / "agent" / "ros2").glob("*.py"))]
    named = re.compile(r"""["'`](%s)\b|def (%s)\(""" % (("|".join(profile.keywords),) * 2))
    hits = [f"{path.relative_to(REPO)}:{number}: {line.strip()}"
            for path in below for number, line in enumerate(path.read_text().splitlines(), start=1)
            if named.search(line)]
    assert hits == []


def test_the_shipped_profiles_load() -> None:
    for path in sorted((REPO / "rsl" / "profiles").glob("*.toml")):
        loaded = load_profile(path)
        assert all(s.binding is not None for s in loaded.skills), path


def test_rebinding_a_skill_keeps_the_adapter_renaming_one_does_not(profile) -> None:
    """The digest an adapter's card pins covers the language, not how the robot does it."""
    from agent.adapter.card import card_path, read_card
    from agent.adapter.prompt import DEFAULT_ADAPTER

    assert profile.digest == read_card(card_path(DEFAULT_ADAPTER)).profile_sha256
    rebound = BASE.replace(FORWARD, '[skills.binding]\nros = "topic"\ntopic = "/creep"\n'
                                    'type = "std_msgs/msg/Float64"\nfields = { data = "distance" }', 1)
    assert parse_profile(rebound).skill("forward").binding.kind == "topic"
    assert parse_profile(rebound).digest == profile.digest
    assert parse_profile(renamed_profile_text()).digest != profile.digest


def test_the_digest_covers_the_language_not_limits_or_wording(profile) -> None:
    """A joint limit or a key the language does not read keeps the adapter; a convention's program does not."""
    limited = BASE.replace("pan = [-1.5708, 1.5708]", "pan = [-1.2, 1.2]", 1)
    assert parse_profile(limited).head["pan"] == (-1.2, 1.2)
    assert parse_profile(limited).digest == profile.digest
    reconvened = BASE.replace('program = "forward 0.5;"', 'program = "forward 0.6;"', 1)
    assert parse_profile(reconvened).digest != profile.digest
