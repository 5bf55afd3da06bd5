"""The config file: defaults, validation, and docs generated from the same dataclasses."""

from __future__ import annotations

from pathlib import Path

import pytest

from agent.daemon.config import Config, ConfigError, load_config, parse_config, render_markdown, render_toml

ROOT = Path(__file__).resolve().parents[2]


def test_docs_config_md_is_generated_from_the_dataclasses() -> None:
    assert (ROOT / "docs" / "config.md").read_text(encoding="utf-8") == render_markdown(), (
        "docs/config.md is stale: run `nrtrans serve --config-doc > docs/config.md`"
    )


def test_printed_config_reads_back_as_the_defaults(tmp_path: Path) -> None:
    path = tmp_path / "config.toml"
    path.write_text(render_toml(), encoding="utf-8")
    assert load_config(path) == Config()


def test_settings_are_read_and_typed() -> None:
    config = parse_config(
        'state_dir = "/tmp/s"\n[api]\nmax_line_bytes = 4096\nallowed_uids = [1000]\n'
        '[robot]\nbackend = "ros2"\nrealtime_factor = 2\n[speech.options]\ndevice = "hw:1"\n'
    )
    assert config.state_path() == Path("/tmp/s")
    assert config.api.max_line_bytes == 4096
    assert config.api.allowed_uids == (1000,)
    assert config.robot.backend == "ros2"
    assert config.robot.realtime_factor == 2.0
    assert config.speech.options == {"device": "hw:1"}


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('[api]\nmax_line_bytes = "big"\n', "api.max_line_bytes must be a whole number"),
        ("[api]\nmax_lines = 3\n", "unknown setting api.max_lines"),
        ('[robot]\nbackend = "gazebo"\n', "robot.backend = 'gazebo' is not one of"),
        ("[tasks]\nqueue_size = 0\n", "tasks.queue_size = 0 is below the minimum 1"),
        ('[api]\nsocket_mode = "rw"\n', "octal"),
        ("api = 3\n", "api must be a table"),
        ("[api\n", "not valid TOML"),
    ],
)
def test_bad_settings_are_errors_that_say_where(text: str, expected: str) -> None:
    with pytest.raises(ConfigError) as caught:
        parse_config(text, source="my.toml")
    assert expected in str(caught.value)
    assert "my.toml" in str(caught.value)


def test_missing_config_file_says_what_to_do(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"(?s)cannot read config file .*help"):
        load_config(tmp_path / "nope.toml")


def test_flags_override_the_file() -> None:
    config = parse_config('[api]\nsocket = "/a.sock"\n').with_overrides(
        socket="/b.sock", state_dir="/st", backend="ros2"
    )
    assert config.socket_path() == Path("/b.sock")
    assert config.audit_path() == Path("/st/audit.jsonl")
    assert config.robot.backend == "ros2"


def test_default_paths_follow_systemd_directories(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RUNTIME_DIRECTORY", "/run/nrtrans")
    monkeypatch.setenv("STATE_DIRECTORY", "/var/lib/nrtrans:/var/lib/other")
    assert Config().socket_path() == Path("/run/nrtrans/nrtrans.sock")
    assert Config().state_path() == Path("/var/lib/nrtrans")
    monkeypatch.delenv("RUNTIME_DIRECTORY")
    monkeypatch.setenv("XDG_RUNTIME_DIR", "/run/user/1000")
    assert Config().socket_path() == Path("/run/user/1000/nrtrans/nrtrans.sock")
