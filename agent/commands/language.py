"""RSL commands: check, compile, grammar, profile show."""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path
from typing import Any

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


def register(subparsers: Any) -> None:
    check = subparsers.add_parser(
        "check", help="check an RSL program and print its diagnostics",
        description="Check an RSL program against the robot profile. Exit status: 0 when the "
                    "program is clean, 1 when it has errors, 2 on a usage error.")
    _source_options(check)
    check.add_argument("--format", choices=["text", "json"], default="text",
                       help="text (default) for people, json for tools")
    check.set_defaults(func=_check)

    compile_ = subparsers.add_parser(
        "compile", help="compile an RSL program to Python, a JSON plan or canonical RSL",
        description="Compile a verified RSL program. Nothing is written when the program has errors.")
    _source_options(compile_)
    compile_.add_argument("-o", "--output", metavar="OUT",
                          help="write here instead of standard output")
    compile_.add_argument("--emit", choices=["python", "plan", "rsl"], default=None,
                          help="output kind; default: python, or plan for a .json OUT")
    compile_.set_defaults(func=_compile)

    grammar = subparsers.add_parser(
        "grammar", help="print the GBNF grammar for llama.cpp constrained sampling",
        description="Print the profile's RSL as a llama.cpp GBNF grammar, in canonical spacing.")
    grammar.add_argument("--profile", metavar="FILE", help="robot profile TOML (default: built-in robot)")
    grammar.add_argument("--objects", metavar="A,B,C", help="narrow object arguments to these names")
    grammar.set_defaults(func=_grammar)

    profile = subparsers.add_parser("profile", help="inspect a robot profile",
                                    description="Inspect a robot profile.")
    actions = profile.add_subparsers(dest="action", metavar="ACTION", required=True)
    show = actions.add_parser("show", help="print the skills, limits and conventions",
                              description="Print the profile as the LLM sees it (text), as the "
                                          "docs show it (markdown), or as JSON.")
    show.add_argument("--profile", metavar="FILE", help="robot profile TOML (default: built-in robot)")
    show.add_argument("--format", choices=["text", "markdown", "json"], default="text")
    show.set_defaults(func=_profile_show)


def _source_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", metavar="FILE", help="RSL program, or - for standard input")
    parser.add_argument("--profile", metavar="FILE", help="robot profile TOML (default: built-in robot)")
    parser.add_argument("--objects", metavar="A,B,C",
                        help="the objects the robot knows; other names are errors")


class UsageError(Exception):
    pass


def _load(args: argparse.Namespace) -> tuple[Any, str, list[str] | None]:
    from rsl.profile import ProfileError, load_profile

    try:
        profile = load_profile(args.profile)
    except ProfileError as exc:
        raise UsageError(str(exc)) from exc
    if args.file == "-":
        source = sys.stdin.read()
    else:
        try:
            source = Path(args.file).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise UsageError(f"cannot read {args.file}: {getattr(exc, 'strerror', None) or exc}") from exc
    return profile, source, _objects(args.objects)


def _objects(text: str | None) -> list[str] | None:
    return None if text is None else [name.strip() for name in text.split(",") if name.strip()]


def _usage_error(exc: Exception) -> int:
    print(f"nrtrans: {exc}", file=sys.stderr)
    return EXIT_USAGE


def _check(args: argparse.Namespace) -> int:
    from rsl.compiler import compile_program

    try:
        profile, source, objects = _load(args)
    except UsageError as exc:
        return _usage_error(exc)
    result = compile_program(source, profile, objects)
    if args.format == "json":
        print(json.dumps({
            "file": args.file,
            "ok": result.ok,
            "diagnostics": [d.to_dict() for d in result.diagnostics],
            "plan": result.plan.to_list() if result.plan else None,
        }, indent=2))
    else:
        for diagnostic in result.diagnostics:
            print(diagnostic.render())
        count = len(result.diagnostics)
        name = "standard input" if args.file == "-" else args.file
        summary = (f"{name}: ok, {len(result.plan or ())} statements" if result.ok
                   else f"{name}: {count} error{'s' if count != 1 else ''}")
        print(summary, file=sys.stderr)
    return EXIT_OK if result.ok else EXIT_ERRORS


def _compile(args: argparse.Namespace) -> int:
    from rsl.codegen import to_python
    from rsl.compiler import compile_program

    try:
        profile, source, objects = _load(args)
    except UsageError as exc:
        return _usage_error(exc)
    result = compile_program(source, profile, objects)
    if not result.ok or result.plan is None:
        for diagnostic in result.diagnostics:
            print(diagnostic.render(), file=sys.stderr)
        count = len(result.diagnostics)
        print(f"{args.file}: not compiled, {count} error{'s' if count != 1 else ''}", file=sys.stderr)
        return EXIT_ERRORS
    emit = args.emit or ("plan" if args.output and args.output.endswith(".json") else "python")
    if emit == "python":
        text = to_python(result.plan, "<stdin>" if args.file == "-" else Path(args.file).name)
    elif emit == "plan":
        text = json.dumps({"profile": result.plan.profile, "commands": result.plan.to_list()}, indent=2) + "\n"
    else:
        text = result.plan.to_rsl()
    if args.output:
        try:
            Path(args.output).write_text(text, encoding="utf-8")
        except OSError as exc:
            return _usage_error(UsageError(f"cannot write {args.output}: {exc.strerror}"))
        print(f"{args.file}: {len(result.plan)} statements -> {args.output}", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return EXIT_OK


def _grammar(args: argparse.Namespace) -> int:
    from rsl.grammar import to_gbnf
    from rsl.profile import ProfileError, load_profile

    try:
        sys.stdout.write(to_gbnf(load_profile(args.profile), _objects(args.objects)))
    except (ProfileError, ValueError) as exc:
        return _usage_error(exc)
    return EXIT_OK


def _profile_show(args: argparse.Namespace) -> int:
    from rsl.describe import language_description, markdown_reference
    from rsl.profile import ProfileError, load_profile

    try:
        profile = load_profile(args.profile)
    except ProfileError as exc:
        return _usage_error(exc)
    if args.format == "markdown":
        sys.stdout.write(markdown_reference(profile))
    elif args.format == "json":
        print(json.dumps({
            "name": profile.name,
            "digest": profile.digest,
            "max_statements": profile.max_statements,
            "workspace": profile.workspace,
            "skills": [{"keyword": s.keyword, "signature": s.signature, "description": s.description,
                        "example": s.example,
                        "params": [{"name": p.name, "kind": p.kind, "unit": p.unit, "min": p.min,
                                    "max": p.max, "axis": p.axis} for p in s.params],
                        "binding": None if s.binding is None else {
                            "form": "primitive" if s.primitive is not None else "ros", **dataclasses.asdict(s.binding),
                            "does": s.binding.describe()}}
                       for s in profile.skills],
            "conventions": [c.__dict__ for c in profile.conventions],
        }, indent=2))
    else:
        sys.stdout.write(language_description(profile))
    return EXIT_OK
