"""`nrtrans demo`: the main job on the embedded defaults."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "fetch_cup.rsl"


def register(subparsers: Any) -> None:
    demo = subparsers.add_parser(
        "demo", help="check and compile the example program",
        description="Check and compile the example RSL program with the default robot profile.")
    demo.set_defaults(func=_demo)


def _demo(args: argparse.Namespace) -> int:
    from rsl.compiler import compile_program
    from rsl.profile import load_profile

    result = compile_program(EXAMPLE.read_text(), load_profile())
    for diagnostic in result.diagnostics:
        print(diagnostic.render(), file=sys.stderr)
    if result.plan is None:
        return 1
    print(result.plan.to_rsl(), end="")
    return 0
