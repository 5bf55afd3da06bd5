"""`nrtrans train-adapter`: teach the embedded model RSL with a LoRA adapter."""

from __future__ import annotations

import argparse
import collections
import dataclasses
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from agent.adapter.recipe import Recipe

if TYPE_CHECKING:
    from agent.adapter.data import Pair

EXIT_USAGE = 2
DEFAULTS = Recipe()


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "train-adapter", help="train the RSL LoRA adapter for a robot profile (needs nrtrans[train])",
        description="Generate (task, RSL program) pairs from the robot profile, fine-tune a LoRA adapter "
                    "for the base GGUF model on them (CPU, or GPU when present), and write it as a "
                    "llama.cpp LoRA adapter GGUF with a JSON card beside it (base model and profile "
                    "hashes, data size, steps, loss, held-out accuracy). Seeded and reproducible. Tasks of "
                    "the evaluation suite and close paraphrases of them are kept out of the data.",
        epilog="Example: nrtrans train-adapter --steps 500 --out my-robot.gguf --profile my-robot.toml\n"
               "Install first: pip install 'torch==2.13.0' && pip install 'nrtrans[train]'",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--profile", metavar="FILE", help="robot profile TOML (default: the built-in robot)")
    parser.add_argument("--model", metavar="NAME|PATH",
                        help="base GGUF model to adapt (default: the embedded Gemma 3 270M)")
    parser.add_argument("--out", metavar="FILE",
                        help="adapter GGUF to write; the card goes beside it as .json (default: the shipped "
                             "adapter for the built-in robot and model, else ./rsl-adapter.gguf)")
    parser.add_argument("--pairs", type=int, default=DEFAULTS.pairs, metavar="N",
                        help=f"training pairs (default {DEFAULTS.pairs})")
    parser.add_argument("--steps", type=int, default=DEFAULTS.steps, metavar="N",
                        help=f"optimizer steps (default {DEFAULTS.steps})")
    parser.add_argument("--batch", type=int, default=DEFAULTS.batch, metavar="N",
                        help=f"pairs per step (default {DEFAULTS.batch})")
    parser.add_argument("--lr", type=float, default=DEFAULTS.learning_rate, metavar="RATE",
                        help=f"peak learning rate (default {DEFAULTS.learning_rate:g})")
    parser.add_argument("--rank", type=int, default=DEFAULTS.rank, metavar="R",
                        help=f"LoRA rank (default {DEFAULTS.rank}; alpha is twice the rank)")
    parser.add_argument("--seed", type=int, default=DEFAULTS.seed,
                        help=f"seed for data, order and weights (default {DEFAULTS.seed})")
    parser.add_argument("--threads", type=int, default=DEFAULTS.threads, metavar="N",
                        help="CPU threads for training (default: every core when the machine is idle, one "
                             "when it is busy; on a CPU shared with other work, one thread was several times "
                             "faster than two that wait for each other)")
    parser.add_argument("--eval", type=int, default=60, metavar="N", dest="eval_pairs",
                        help="held-out synthetic pairs to score the adapter on with llama.cpp (default 60; "
                             "0 skips)")
    parser.add_argument("--checkpoint-every", type=int, default=0, metavar="N",
                        help="also write the adapter every N steps as OUT.stepN.gguf, for a learning curve "
                             "(default 0: never)")
    parser.add_argument("--dump-data", metavar="FILE", help="also write the training pairs here as JSON lines")
    moved = parser.add_mutually_exclusive_group()
    moved.add_argument("--save-examples", metavar="FILE",
                       help="generate and encode the training pairs, write them to FILE (gzipped JSON) and stop; "
                            "for training on another machine, such as a GPU one whose transformers splits "
                            "text unlike llama.cpp")
    moved.add_argument("--examples", metavar="FILE",
                       help="train from pairs encoded by --save-examples (same --profile and --model) instead "
                            "of generating them; --pairs is then the file's, and --seed sets the order and "
                            "the weights only")
    parser.set_defaults(func=_train)


def _fail(message: str) -> int:
    print(f"nrtrans train-adapter: error: {message}", file=sys.stderr)
    return 1


def _train(args: argparse.Namespace) -> int:
    for name in ("pairs", "steps", "batch", "rank"):
        if getattr(args, name) < 1:
            print(f"nrtrans train-adapter: error: --{name} must be at least 1", file=sys.stderr)
            return EXIT_USAGE
    if args.threads < 0:
        print("nrtrans train-adapter: error: --threads must be 0 (automatic) or more", file=sys.stderr)
        return EXIT_USAGE
    if args.examples and args.dump_data:
        print("nrtrans train-adapter: error: --dump-data writes generated pairs, and --examples generates none; "
              "dump them where the examples were saved", file=sys.stderr)
        return EXIT_USAGE
    from agent.adapter.card import AdapterCard, card_path, sha256_of
    from agent.adapter.data import data_digest, generate, pair_record
    from agent.adapter.examples import EncodedExamples, read_examples
    from agent.adapter.hygiene import eval_tasks, held_out_filter
    from agent.adapter.prompt import DEFAULT_ADAPTER, PROMPT_VERSION
    from agent.adapter.train import TrainingError, require_train_extra, train, train_encoded
    from agent.translate import ModelNotFoundError
    from agent.translate.model_path import resolve_model
    from rsl.profile import ProfileError, load_profile

    try:
        require_train_extra()
        profile = load_profile(args.profile)
        base = resolve_model(args.model)
    except (TrainingError, ProfileError, ModelNotFoundError) as exc:
        return _fail(str(exc))
    default_setup = args.profile is None and args.model in (None, "", "default")
    out = Path(args.out) if args.out else (DEFAULT_ADAPTER if default_setup else Path("rsl-adapter.gguf"))

    started = time.monotonic()
    suite = eval_tasks()
    excluded_by_suite = held_out_filter(suite)
    base_sha = sha256_of(base)
    encoded: EncodedExamples | None = None
    pairs: list[Pair] = []
    try:
        if args.examples:
            encoded = read_examples(Path(args.examples))
            encoded.check_fits(base_sha, profile.digest, PROMPT_VERSION)
            print(f"training on {len(encoded.examples)} pairs encoded in {args.examples}", file=sys.stderr)
            seen = set(encoded.normalized)
        else:
            print(f"generating {args.pairs} training pairs from profile {profile.name!r} "
                  f"(keeping {len(suite)} eval-suite tasks and their paraphrases out) ...", file=sys.stderr)
            pairs = generate(profile, args.pairs, seed=args.seed, exclude=excluded_by_suite)
            seen = {p.normalized for p in pairs}
        held_out = generate(profile, args.eval_pairs, seed=args.seed + 1_000_003,
                            exclude=lambda text: text in seen or excluded_by_suite(text)) \
            if args.eval_pairs and not args.save_examples else []
    except (ValueError, RuntimeError) as exc:
        return _fail(str(exc))
    if args.dump_data:
        with open(args.dump_data, "w", encoding="utf-8") as handle:
            for pair in pairs:
                handle.write(json.dumps(pair_record(pair)) + "\n")
    if args.save_examples:
        return _save_examples(Path(args.save_examples), pairs, base, base_sha, profile, args.seed)

    threads = args.threads or _auto_threads()
    print(f"training with {threads} CPU thread(s)", file=sys.stderr)

    recipe = dataclasses.replace(DEFAULTS, pairs=encoded.pairs if encoded else args.pairs, steps=args.steps,
                                 batch=args.batch, learning_rate=args.lr, rank=args.rank, alpha=2.0 * args.rank,
                                 seed=args.seed, threads=threads, checkpoint_every=args.checkpoint_every)
    metadata = {"base_model_sha256": base_sha, "profile_sha256": profile.digest,
                "prompt_version": str(PROMPT_VERSION)}
    try:
        if encoded is not None:
            result = train_encoded(encoded.examples, base, out, recipe, metadata=metadata)
        else:
            result = train(pairs, base, out, recipe, metadata=metadata)
    except TrainingError as exc:
        return _fail(str(exc))

    import torch
    import transformers

    if encoded is not None:
        data = {"pairs": encoded.pairs, "encoded": result.examples, "seed": encoded.seed,
                "groups": encoded.groups, "encoded_with_transformers": encoded.transformers}
    else:
        data = {"pairs": len(pairs), "encoded": result.examples, "seed": args.seed, "groups": _groups(pairs),
                "sha256": data_digest(pairs)}
    card = AdapterCard(
        adapter_file=out.name, adapter_sha256=sha256_of(out), base_model_file=base.name,
        base_model_sha256=base_sha, profile_name=profile.name, profile_sha256=profile.digest,
        prompt_version=PROMPT_VERSION,
        data={**data, "held_out_pairs": len(held_out), "eval_suite_tasks_excluded": len(suite)},
        training={"seed": args.seed, "steps": result.steps, "batch": recipe.batch,
                  "learning_rate": recipe.learning_rate, "rank": recipe.rank, "alpha": recipe.alpha,
                  "bf16_base": result.bf16,
                  "first_loss": round(result.first_loss, 4), "final_loss": round(result.final_loss, 4),
                  "loss_every_50": [round(x, 4) for x in result.losses[::50]],
                  "train_seconds": round(result.seconds, 1),
                  "total_seconds": round(time.monotonic() - started, 1), "device": result.device,
                  "threads": recipe.threads, "torch": torch.__version__,
                  "transformers": transformers.__version__, "machine": platform.machine()})
    # Written before scoring too: the runtime reads the card (prompt format) when it loads the adapter.
    card.write(card_path(out))
    if held_out:
        card = dataclasses.replace(card, eval=_score(base, out, held_out, profile, threads))
        card.write(card_path(out))
    print(f"wrote {out} and {card_path(out)}", file=sys.stderr)
    if card.eval:
        print(json.dumps(card.eval, indent=2))
    return 0


def _save_examples(path: Path, pairs: list[Pair], base: Path, base_sha: str, profile: Any, seed: int) -> int:
    """Encode `pairs` with this machine's tokenizer, checked against llama.cpp's, and write them to `path`."""
    import transformers

    from agent.adapter.examples import EncodedExamples
    from agent.adapter.prompt import PROMPT_VERSION
    from agent.adapter.train import TrainingError, encode_checked, load_tokenizer

    print(f"encoding {len(pairs)} pairs with the tokenizer of {base.name} ...", file=sys.stderr)
    try:
        encoded = encode_checked(load_tokenizer(base), base, pairs)
    except TrainingError as exc:
        return _fail(str(exc))
    examples = tuple((tuple(ids), tuple(labels)) for ids, labels in encoded)
    EncodedExamples(examples=examples, base_model_sha256=base_sha, profile_name=profile.name,
                    profile_sha256=profile.digest, prompt_version=PROMPT_VERSION, seed=seed, pairs=len(pairs),
                    groups=_groups(pairs), normalized=tuple(p.normalized for p in pairs),
                    transformers=transformers.__version__).write(path)
    print(f"wrote {len(examples)} encoded pairs to {path}. Train from them on any machine with nrtrans[train] "
          f"and the same base model:\n  nrtrans train-adapter --examples {path}", file=sys.stderr)
    return 0


def _groups(pairs: list[Pair]) -> dict[str, int]:
    """Pairs per group, in the order the groups first appear."""
    return dict(collections.Counter(pair.group for pair in pairs))


def _auto_threads() -> int:
    cores = os.cpu_count() or 1
    return cores if os.getloadavg()[0] < 1.0 else 1


def _score(base: Path, adapter: Path, held_out: list[Any], profile: Any, threads: int) -> dict[str, Any]:
    """The card's eval figures: held-out pairs by the adapter alone and as the runtime runs them, and
    the evaluation suite when it is written for this profile."""
    from agent.adapter.evaluate import evaluate, evaluate_translator, load
    from agent.evalsuite import load_suite
    from agent.evalsuite.runner import render_table, run_suite, summarize
    from agent.evalsuite.suite import SuiteError
    from agent.translate import Translator

    def report(done: int, total: int) -> None:
        if done % 20 == 0 or done == total:
            print(f"  {done}/{total}", file=sys.stderr, flush=True)

    print(f"scoring the adapter alone on {len(held_out)} held-out synthetic pairs with llama.cpp ...",
          file=sys.stderr)
    alone = evaluate(load(base, adapter, threads=threads or None), held_out, profile, progress=report)
    for task, want, got in alone.failures[:5]:
        print(f"  miss: {task!r}\n    want {want.strip()!r}\n    got  {got.strip()!r}", file=sys.stderr)
    scores: dict[str, Any] = {"synthetic_held_out": alone.to_dict()}
    translator = Translator.load(profile, model=str(base), adapter=str(adapter))
    try:
        print("scoring it as the runtime runs it (clauses, grammar, repair) ...", file=sys.stderr)
        scores["synthetic_held_out_runtime"] = evaluate_translator(translator, held_out, profile,
                                                                   progress=report).to_dict()
        try:
            tasks = load_suite(profile=profile)
        except SuiteError as exc:
            print(f"not running the evaluation suite: {exc}", file=sys.stderr)
        else:
            print(f"running the evaluation suite ({len(tasks)} tasks) ...", file=sys.stderr)
            table = summarize(run_suite(translator, tasks, profile))
            print(render_table(table), file=sys.stderr)
            scores["eval_suite"] = {group: {"n": int(row["n"]), "accuracy": round(row["accuracy"], 4),
                                            "verified": round(row["success"], 4),
                                            "latency_p50_ms": round(row["latency_p50_ms"], 1)}
                                    for group, row in table.items()}
    finally:
        translator.close()
    return scores
