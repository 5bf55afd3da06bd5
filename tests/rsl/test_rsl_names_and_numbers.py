"""Names are ASCII C identifiers and numbers plain decimals: anything else gets a clear diagnostic."""

from __future__ import annotations

import pytest

from agent.cli import main
from rsl.compiler import compile_program
from rsl.diagnostics import Code


@pytest.mark.parametrize(("program", "token", "advice"), [
    ("approach x²;", "x²", "write `x2` instead"),
    ("grasp café;", "café", "write `cafe` instead"),
    ("grasp 杯子;", "杯子", "use an ASCII name"),
    ("goto ٣, 1;", "٣", "plain decimal"),
])
def test_non_ascii_names_and_digits_are_refused(profile, program, token, advice):
    result = compile_program(program, profile)
    assert not result.ok
    (diagnostic,) = result.diagnostics
    assert diagnostic.token == token and advice in diagnostic.message, diagnostic.message
    assert diagnostic.code in (Code.ILLEGAL_IDENTIFIER, Code.ILLEGAL_NUMBER)


@pytest.mark.parametrize(("text", "advice"), [
    ("0x10", "no C hexadecimal numbers; write it in decimal, `16`"),
    ("0b11", "no C binary numbers; write it in decimal, `3`"),
    ("010", "octal in C, which RSL does not have; write `10`"),
    ("0xZZ", "write it as a plain decimal"),
])
def test_c_integer_spellings_are_illegal_numbers_not_names(profile, text, advice):
    (diagnostic,) = compile_program(f"forward {text};", profile).diagnostics
    assert diagnostic.code is Code.ILLEGAL_NUMBER and diagnostic.token == text
    assert advice in diagnostic.message, diagnostic.message


@pytest.mark.parametrize("text", ["0", "0.5", "10", "01.5", "1e1", ".5"])
def test_plain_decimals_still_parse(profile, text):
    assert not [d for d in compile_program(f"forward {text};", profile).diagnostics if not d.code.is_semantic]


@pytest.mark.parametrize("program", ["approach x²;\n", "grasp café;\nforward 0x10;\n"])
def test_compile_command_reports_instead_of_crashing(tmp_path, capsys, program):
    source = tmp_path / "prog.rsl"
    source.write_text(program, encoding="utf-8")
    assert main(["compile", str(source)]) == 1
    captured = capsys.readouterr()
    count = program.count(";")
    assert captured.err.endswith(f"not compiled, {count} error{'s' if count > 1 else ''}\n"), captured.err
    assert "error[E00" in captured.err and captured.out == ""


def test_compiled_python_ends_with_one_newline(tmp_path, capsys):
    source = tmp_path / "prog.rsl"
    source.write_text("forward 1;\n", encoding="utf-8")
    assert main(["compile", str(source)]) == 0
    out = capsys.readouterr().out
    assert out.endswith(")\n") and not out.endswith("\n\n")
    target = tmp_path / "prog.py"
    assert main(["compile", str(source), "-o", str(target)]) == 0
    assert target.read_text().endswith(")\n")
