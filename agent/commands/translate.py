"""`nrtrans translate`: one task in, a verified RSL program out."""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from typing import Any

EXIT_VERIFIED, EXIT_UNVERIFIED, EXIT_USAGE = 0, 1, 2


def add_model_options(parser: argparse.ArgumentParser) -> None:
    """Options shared by `translate` and `eval`."""
    parser.add_argument("--model", metavar="NAME|PATH",
                        help="GGUF model file or a name from `nrtrans models list` "
                             "(default: the embedded Gemma 3 270M)")
    parser.add_argument("--adapter", metavar="PATH|default|none",
                        help="LoRA adapter GGUF, `default` for the shipped RSL adapter, or `none` for the base "
                             "model prompted with worked examples (default: the shipped adapter when the model "
                             "and the profile are the ones it was trained for, see docs/adapter.md)")
    parser.add_argument("--max-passes", type=int, default=3, metavar="N",
                        help="generate-and-compile passes before giving up (default: 3)")
    parser.add_argument("--no-grammar", action="store_true",
                        help="sample without the RSL grammar (the unconstrained setting, for comparison)")
    parser.add_argument("--shots", type=int, default=None, metavar="N",
                        help="worked examples picked by similarity to each clause, after the fixed prompt "
                             "(default: 0; every example is already in the fixed prefix)")
    parser.add_argument("--no-prefix-shots", action="store_true",
                        help="leave the worked examples out of the fixed, KV-cached prompt prefix "
                             "(then use --shots N to pick similar ones per clause)")
    clauses = parser.add_mutually_exclusive_group()
    clauses.add_argument("--no-split", action="store_true",
                         help="translate the task in one go instead of clause by clause (the default with the "
                              "adapter)")
    clauses.add_argument("--split", action="store_true",
                         help="split the task into clauses and translate them one by one (the default "
                              "without the adapter)")
    parser.add_argument("--no-narrow", action="store_true",
                        help="do not narrow the grammar to the objects and numbers the task mentions")
    parser.add_argument("--profile", metavar="FILE", help="robot profile TOML (default: the built-in robot)")
    parser.add_argument("--endpoint", metavar="URL",
                        help="use an OpenAI-compatible server (llama.cpp's) at URL instead of the local model")


def load_translator(args: argparse.Namespace) -> Any:
    """A Translator for the parsed options; raises with a clear message on bad ones."""
    from agent.translate import Translator
    from rsl.profile import load_profile

    if args.max_passes < 1:
        raise ValueError(f"--max-passes must be at least 1, got {args.max_passes}")
    profile = load_profile(args.profile)
    return Translator.load(profile, model=args.model, adapter=args.adapter, grammar=not args.no_grammar,
                           max_passes=args.max_passes, endpoint=args.endpoint, shots=args.shots,
                           split_clauses=True if args.split else (False if args.no_split else None),
                           narrow=not args.no_narrow,
                           prefix_shots=not args.no_prefix_shots)


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "translate", help="translate a task into a verified RSL program",
        description="Translate a task in plain language into an RSL program with the on-device LLM, "
                    "sampling under the RSL grammar and repairing it with the compiler's diagnostics. "
                    "Prints the verified program. Exit status: 0 verified, 1 not verified, 2 usage error.",
        epilog='Example: nrtrans translate "move forward two meters, then grasp the cup" --objects cup')
    parser.add_argument("task", help="the task, in quotes")
    parser.add_argument("--json", action="store_true",
                        help="print one JSON object: task, program, verified, passes, attempts, plan, "
                             "model, timings_ms, explanation, confidence, doubts, confirm (true when the "
                             "default confirm policy would ask before running it), refused")
    parser.add_argument("--objects", metavar="A,B",
                        help="objects the robot knows; other object names are errors to repair")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="show on standard error what happens: the clauses, each pass's program and "
                             "diagnostics, and the timings")
    add_model_options(parser)
    parser.set_defaults(func=_translate)


def parse_objects(text: str | None) -> list[str] | None:
    if text is None:
        return None
    return [name.strip() for name in text.split(",") if name.strip()]


def _translate(args: argparse.Namespace) -> int:
    from agent.translate import ModelNotFoundError
    from agent.translate.http import EndpointError
    from rsl.profile import ProfileError

    if not args.task.strip():
        print("nrtrans translate: error: the task is empty.\n  Give the task in quotes, e.g. "
              "nrtrans translate \"turn left 90 degrees\"", file=sys.stderr)
        return EXIT_USAGE
    if args.verbose:
        _show_progress()
    loading = time.perf_counter()
    try:
        translator = load_translator(args)
    except (ModelNotFoundError, ProfileError, EndpointError, ValueError) as exc:
        print(f"nrtrans translate: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    logging.getLogger("nrtrans.translate").debug("model %s loaded in %.1f s", translator.model_name,
                                                 time.perf_counter() - loading)

    def show(attempt: Any) -> None:
        if args.verbose:
            for diagnostic in attempt.diagnostics:
                print(diagnostic.render(), file=sys.stderr, end="")

    try:
        result = translator.translate(args.task, known_objects=parse_objects(args.objects), on_attempt=show)
    except (EndpointError, ValueError) as exc:
        print(f"nrtrans translate: error: {exc}", file=sys.stderr)
        return EXIT_UNVERIFIED
    finally:
        translator.close()
    if args.json:
        print(json.dumps(result.to_json_dict(), indent=2))
    elif result.verified:
        print(result.program, end="")
        print(_explained(result), file=sys.stderr)
    elif result.refused:
        from agent.translate.explain import capabilities
        from rsl.diagnostics import Code

        why = next(d.message for d in result.attempts[-1].diagnostics if d.code is Code.NOT_A_TASK)
        print(f"nrtrans translate: {args.task.strip()!r} was not understood as a task for this robot, so there "
              f"is no program.\n  = note: {why}\n  = help: say what the robot should do. It can: "
              f"{capabilities(translator.profile)}.", file=sys.stderr)
    else:
        print(f"nrtrans translate: could not verify a program in {result.passes} pass(es); "
              "the last attempt was:", file=sys.stderr)
        print(result.program, file=sys.stderr, end="")
        for diagnostic in result.attempts[-1].diagnostics if result.attempts else ():
            print(diagnostic.render(), file=sys.stderr, end="")
    return EXIT_VERIFIED if result.verified else EXIT_UNVERIFIED


def _explained(result: Any) -> str:
    """The plan in words and how sure the translation is, with why when it would ask first."""
    text = f"-> {result.explanation}"
    if result.confidence is not None:
        text += f"\n   confidence {result.confidence:.2f}"
        if result.confirm:
            text += "; nrtrans serve would ask before running it: " + "; ".join(result.doubts)
    return text


def _show_progress() -> None:
    """The translation loop's progress lines on standard error, each prefixed `translate:`."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("translate: %(message)s"))
    progress = logging.getLogger("nrtrans.translate")
    progress.addHandler(handler)
    progress.setLevel(logging.DEBUG)
