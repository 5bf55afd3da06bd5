"""`nrtrans check|compile|grammar|profile` from the command line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from agent.cli import main
from rsl.describe import markdown_reference

ROOT = Path(__file__).resolve().parents[2]


def _write(tmp_path, text, name="prog.rsl"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_check_exit_codes(tmp_path, capsys):
    assert main(["check", _write(tmp_path, "forward 1;\n")]) == 0
    assert main(["check", _write(tmp_path, "move 1;\n")]) == 1
    assert "did you mean `forward`" in capsys.readouterr().out
    assert main(["check", str(tmp_path / "missing.rsl")]) == 2
    assert "cannot read" in capsys.readouterr().err
    with pytest.raises(SystemExit) as usage:
        main(["check"])
    assert usage.value.code == 2


def test_check_json_is_machine_readable(tmp_path, capsys):
    assert main(["check", "--format", "json", _write(tmp_path, "goto 1;\nforward x;\n")]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] is False and report["plan"] is None
    assert [(d["code"], d["line"], d["column"], d["token"]) for d in report["diagnostics"]] == [
        ("E008", 1, 1, "goto"), ("E007", 2, 9, "x")]


def test_check_reads_standard_input_and_known_objects():
    run = subprocess.run([sys.executable, "-m", "agent.cli", "check", "--objects", "cup", "-"],
                         input="grasp mug;\n", capture_output=True, text=True, timeout=60)
    assert run.returncode == 1 and "E104" in run.stdout


def test_compile_writes_python_that_compiles(tmp_path):
    out = tmp_path / "prog.py"
    assert main(["compile", _write(tmp_path, "forward 1; turnleft 1.5708;"), "-o", str(out)]) == 0
    compile(out.read_text(), str(out), "exec")


def test_compile_refuses_a_bad_program_and_writes_nothing(tmp_path):
    out = tmp_path / "prog.py"
    assert main(["compile", _write(tmp_path, "forward -1;"), "-o", str(out)]) == 1
    assert not out.exists()


def test_compile_plan_json(tmp_path):
    out = tmp_path / "plan.json"
    assert main(["compile", _write(tmp_path, "grasp cup;"), "-o", str(out)]) == 0
    assert json.loads(out.read_text())["commands"][0]["args"] == [{"object": "cup"}]


def test_grammar_command(capsys):
    assert main(["grammar", "--objects", "cup,table"]) == 0
    assert 'object ::= "cup" | "table"' in capsys.readouterr().out
    assert main(["grammar", "--objects", "not an id"]) == 2


def test_profile_show_formats(capsys):
    assert main(["profile", "show"]) == 0
    assert "`goto X, Y;`" in capsys.readouterr().out
    assert main(["profile", "show", "--format", "json"]) == 0
    assert len(json.loads(capsys.readouterr().out)["skills"]) == 12


def test_docs_language_reference_is_generated_from_the_profile(profile):
    assert (ROOT / "docs" / "language.md").read_text() == markdown_reference(profile), (
        "docs/language.md is stale: run `nrtrans profile show --format markdown > docs/language.md`")


def test_every_command_has_help():
    from agent.cli import build_parser

    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    for name, sub in commands.items():
        assert sub.format_help().strip(), name
        assert sub.description or sub.format_usage(), name
