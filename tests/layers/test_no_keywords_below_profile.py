"""Below the profile, no runtime module names a default skill keyword.

A robot with other skills needs only another profile: so no code string may
be a default keyword (`"grasp"`, a ROS name `"/grasp"`), hold an RSL statement
that uses one (`"goto 1, 2;"`, f"approach {name};") or quote one as a command
(`` `perceive` ``). English prose that happens to use the word ("cannot grasp
the cup", "driving forward") is not code that knows the keyword. Docstrings
are documentation and are not searched. The keywords come from the default
profile itself, not from a copy here.

`pytest tests/layers -s` prints what was searched.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path

from rsl.profile import load_profile
from tests.layers.modules import ROOT, runtime_modules

# (module path, the exact string) -> why it may stay. Keep it short.
ALLOWED: dict[tuple[str, str], str] = {}

KEYWORDS = load_profile().keywords
_WORD = "|".join(KEYWORDS)
_ARG = r"[-\w.]+"
RULES = (
    ("is a keyword or its ROS name", re.compile(rf"/?({_WORD})\Z")),
    ("holds an RSL statement", re.compile(rf"\b({_WORD})\b(\s+{_ARG}(\s*,\s*{_ARG})*)?\s*;")),
    ("quotes a keyword as a command", re.compile(rf"`({_WORD})\b")),
)


def _docstrings(tree: ast.AST) -> set[int]:
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) \
                    and isinstance(first.value.value, str):
                found.add(id(first.value))
    return found


def code_strings(source: str) -> Iterator[tuple[int, str]]:
    """Every string constant that is not a docstring, with its line; an f-string as one text with `X` for
    each placeholder, so f"approach {name};" reads as "approach X;"."""
    tree = ast.parse(source)
    skip = _docstrings(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            skip.update(id(part) for part in node.values)
            yield node.lineno, "".join(p.value if isinstance(p, ast.Constant) else "X" for p in node.values)
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip:
            yield node.lineno, node.value


def offences(path: Path, source: str) -> list[str]:
    where = str(path.relative_to(ROOT)) if path.is_absolute() else str(path)
    found = []
    for line, text in sorted(code_strings(source)):
        if (where, text) in ALLOWED:
            continue
        for rule, pattern in RULES:
            if pattern.match(text) if rule.startswith("is a") else pattern.search(text):
                found.append(f"{where}:{line}: {text!r} {rule}")
                break
    return found


def test_no_runtime_module_names_a_default_keyword() -> None:
    modules = runtime_modules()
    found = [o for path in modules for o in offences(path, path.read_text(encoding="utf-8"))]
    checked = sum(1 for path in modules for _ in code_strings(path.read_text(encoding="utf-8")))
    print(f"\nsearched {checked} code strings in {len(modules)} runtime modules of agent/ and rsl/ "
          f"for the keywords {', '.join(KEYWORDS)}: {len(found)} found")
    assert not found, ("runtime modules name default skill keywords; take the word from the profile "
                       "(e.g. profile.bound_to(primitive)) instead:\n  " + "\n  ".join(found))
    assert len(modules) > 50, "the search found too few modules to prove anything"
    assert not any("adapter/data.py" in str(p) for p in modules), "training code is not runtime code"


def test_the_search_finds_each_kind_of_naming() -> None:
    named = '''
"""A docstring may say `grasp cup;`."""
if skill == "grasp": pass
service = "/perceive"
hint = "write `goto 1, 2;`"
advice = f"or `approach {name};` to stop in front of it"
note = "none yet (use `perceive` first)"
fine = "cannot grasp the cup: the gripper is full"
also_fine = "driving forward"
'''
    found = offences(Path("example.py"), named)
    assert [entry.split(":")[1] for entry in found] == ["3", "4", "5", "6", "7"], found
