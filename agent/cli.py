"""The `nrtrans` command line: one sub-command per module in `agent.commands`.

Each module there defines `register(subparsers)` and adds its own commands,
so a new command never edits this file. Modules import heavy dependencies
inside their handlers, which keeps `nrtrans --help` instant.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from collections.abc import Sequence

import agent.commands


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="nrtrans",
        description="Turn spoken or typed robot tasks into verified RSL programs and run them.",
        epilog="Run `nrtrans COMMAND --help` for the options of one command.",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module_info in sorted(pkgutil.iter_modules(agent.commands.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"agent.commands.{module_info.name}")
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        print("nrtrans: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    sys.exit(main())
