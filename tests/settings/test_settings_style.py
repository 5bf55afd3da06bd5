"""Every section of settings is read by one mechanism, so its errors look the same.

The daemon's config file, the speech input's `[speech.options]` and a profile's
`[ros]` table: an unknown key names the key, every key the section has and
where they are described; a value of the wrong type names the key, the type
wanted and the value given.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable
from typing import Any

import pytest

from agent.daemon.config import (
    ApiConfig,
    AuditConfig,
    Config,
    ConfigError,
    RobotConfig,
    TasksConfig,
    TranslatorConfig,
    parse_config,
)
from agent.ros2.config import RosConfig
from agent.speech import SpeechConfig, SpeechConfigError
from rsl.profile import ProfileError


def _toml(value: Any) -> str:
    return f'"{value}"' if isinstance(value, str) else str(value)


def _daemon(table: str) -> Callable[[dict[str, Any]], object]:
    def read(values: dict[str, Any]) -> object:
        return parse_config(f"[{table}]\n" + "".join(f"{k} = {_toml(v)}\n" for k, v in values.items()),
                            source="my.toml")
    return read


# (section, reader, error, file named in messages, key prefix, docs, a key with a wrong value, the type wanted)
SECTIONS = [
    ("daemon [api]", _daemon("api"), ConfigError, "my.toml", "api.", "docs/config.md",
     ("max_line_bytes", "big"), "a whole number"),
    ("daemon [translator]", _daemon("translator"), ConfigError, "my.toml", "translator.", "docs/config.md",
     ("grammar", "yes"), "true or false"),
    ("[speech.options]", SpeechConfig.from_dict, SpeechConfigError, "", "speech.", "docs/speech.md",
     ("silence_ms", "long"), "a whole number"),
    ("profile [ros]", lambda values: RosConfig.from_mapping(values, source="my.toml"), ProfileError, "my.toml",
     "ros.", "docs/ros2.md", ("odom_timeout", "fast"), "a number"),
]


@pytest.mark.parametrize(("section", "read", "error", "source", "prefix", "docs", "bad", "wanted"), SECTIONS,
                         ids=[s[0] for s in SECTIONS])
def test_an_unknown_key_and_a_wrong_type_read_the_same_in_every_section(
        section: str, read: Callable[[dict[str, Any]], object], error: type[Exception], source: str, prefix: str,
        docs: str, bad: tuple[str, Any], wanted: str) -> None:
    where = re.escape(f"{source}: ") if source else ""
    with pytest.raises(error) as unknown:
        read({"no_such_setting": 1})
    assert re.fullmatch(rf"{where}unknown setting {re.escape(prefix)}no_such_setting\n"
                        rf"  = help: the settings here are {re.escape(prefix)}\w+(, {re.escape(prefix)}\w+)*; "
                        rf"see {re.escape(docs)}", str(unknown.value)), str(unknown.value)
    key, value = bad
    with pytest.raises(error) as wrong:
        read({key: value})
    assert str(wrong.value) == f"{source + ': ' if source else ''}{prefix}{key} must be {wanted}, not {value!r}"


@pytest.mark.parametrize(("read", "values", "error", "message"), [
    (_daemon("tasks"), {"queue_size": 0}, ConfigError, "my.toml: tasks.queue_size = 0 is below the minimum 1"),
    (SpeechConfig.from_dict, {"sample_rate": 96000}, SpeechConfigError,
     "speech.sample_rate = 96000 is above the maximum 48000"),
    (lambda values: RosConfig.from_mapping(values, source="my.toml"), {"goal_tolerance": 0}, ProfileError,
     "my.toml: ros.goal_tolerance = 0 is not above 0.0"),
    (_daemon("robot"), {"backend": "gazebo"}, ConfigError,
     "my.toml: robot.backend = 'gazebo' is not one of 'sim', 'ros2'"),
    (SpeechConfig.from_dict, {"wake_words": ["robot", 3]}, SpeechConfigError,
     "speech.wake_words must be a list of strings, not ['robot', 3]"),
    (SpeechConfig.from_dict, {"device": 1.5}, SpeechConfigError,
     "speech.device must be a string or a whole number, not 1.5"),
    (lambda values: RosConfig.from_mapping(values), {"cmd_vel": ""}, ProfileError,
     "<profile>: ros.cmd_vel must not be empty"),
])
def test_bounds_choices_and_compound_types_are_checked_alike(read: Callable[[dict[str, Any]], object],
                                                             values: dict[str, Any], error: type[Exception],
                                                             message: str) -> None:
    with pytest.raises(error) as caught:
        read(values)
    assert str(caught.value) == message


def test_good_values_are_typed_by_the_field() -> None:
    speech = SpeechConfig.from_dict({"wake_words": ["hey", "robot"], "max_utterance_s": 10, "device": 3})
    assert speech.wake_words == ("hey", "robot") and speech.max_utterance_s == 10.0 and speech.device == 3
    assert isinstance(RosConfig.from_mapping({"goal_tolerance": 1}).goal_tolerance, float)


@pytest.mark.parametrize("section", [Config, ApiConfig, TasksConfig, TranslatorConfig, RobotConfig, AuditConfig,
                                     SpeechConfig, RosConfig])
def test_every_setting_is_documented_in_its_field(section: type) -> None:
    undocumented = [f.name for f in dataclasses.fields(section) if not f.metadata.get("doc")]
    assert not undocumented, f"{section.__name__}: fields without a doc: {undocumented}"
