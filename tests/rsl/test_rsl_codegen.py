"""The emitted Python program: valid, in order, and never an injection path."""

from __future__ import annotations

import ast

from rsl.codegen import to_python
from rsl.compiler import compile_program
from rsl.plan import Command, ObjectRef, Plan
from rsl.profile import parse_profile


def _calls(code):
    tree = ast.parse(code)
    run = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "run")
    return [(c.func.attr, [ast.literal_eval(a) for a in c.args])
            for c in ast.walk(run) if isinstance(c, ast.Call) and isinstance(c.func, ast.Attribute)
            and isinstance(c.func.value, ast.Name) and c.func.value.id == "robot"]


def test_one_call_per_statement_in_order(profile):
    plan = compile_program("forward 1.5;\nturnleft 1.5708;\napproach table;\ngoto -1, 2;\nperceive;", profile).plan
    code = to_python(plan, "square.rsl")
    compile(code, "square.py", "exec")
    assert _calls(code) == [("forward", [1.5]), ("turnleft", [1.5708]), ("approach", ["table"]),
                            ("goto", [-1.0, 2.0]), ("perceive", [])]


def test_source_text_never_reaches_the_output(profile):
    hostile = 'forward 1; // """; import os; os.system("rm -rf /")\n/* __import__("os") */ grasp cup;'
    code = to_python(compile_program(hostile, profile).plan, 'evil"""\nimport os.rsl')
    compile(code, "x.py", "exec")
    assert "os.system" not in code and "__import__" not in code and "rm -rf" not in code
    module = ast.parse(code)
    imports = {a.name for n in ast.walk(module) if isinstance(n, ast.Import | ast.ImportFrom) for a in n.names}
    assert imports <= {"sys", "CancelToken", "Outcome", "Robot", "open_robot", "load_profile"}


def test_generated_program_runs_against_a_robot_object(profile):
    calls = []

    class Recorder:
        def __getattr__(self, name):
            def skill(*args, cancel):
                calls.append((name, args))
                from agent.robot import Outcome
                return Outcome.failed("blocked") if name == "grasp" else Outcome.done()
            return skill

    namespace: dict = {"__name__": "generated"}
    exec(compile(to_python(compile_program("forward 1; grasp cup; perceive;", profile).plan), "g", "exec"),
         namespace)
    outcome = namespace["run"](Recorder())
    assert not outcome.ok and outcome.reason == "blocked"
    assert calls == [("forward", (1.0,)), ("grasp", ("cup",))]


def test_object_names_are_quoted_as_data(profile):
    plan = Plan((Command("grasp", (ObjectRef("cup"),), 1, 1),), profile.name)
    assert "robot.grasp('cup', cancel=cancel)" in to_python(plan)


def test_profile_cannot_smuggle_code_through_a_keyword():
    import pytest

    from rsl.profile import ProfileError

    bad = '[[skills]]\nkeyword = "x(); import os; y"\ndescription = "d"\nexample = "x;"\nparams = []\n'
    with pytest.raises(ProfileError):
        parse_profile(bad)
