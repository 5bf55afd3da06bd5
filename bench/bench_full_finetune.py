"""Issue 10's capacity question: fine-tune every projection weight of the 270M model, not a rank-16 LoRA.

The shipped adapter trains 3.8 M LoRA weights; rank 32 changed nothing
measurable. This trains the full q/k/v/o and gate/up/down matrices of all
layers (about 100 M weights; the embeddings and norms stay frozen) on the
same 20,000 pairs, with the same seed, batches and schedule as the shipped
recipe, so only the capacity differs.

The fine-tuned weights minus the base weights are written exactly, as a
llama.cpp LoRA adapter of full rank (a delta D of shape out x in becomes
B = D, A = I, or A = D, B = I, whichever is smaller): the runtime, the
grammar and the benches then load it like any adapter, and quantization
does not blur the comparison. Shipping a winner would mean merging and
quantizing instead; that is only worth doing if it wins.

    python bench/bench_full_finetune.py --out /tmp/full/full.gguf          # train and export
    python bench/bench_full_finetune.py --out /tmp/full/probe.gguf --steps 20 --time-only
    python bench/bench_confidence.py --adapter /tmp/full/full.gguf --suite bench/fresh/dev.toml --out ...

Writes the training figures as JSON (--json, default bench/results/full_finetune_training.json).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import random
import sys
import time
from pathlib import Path
from typing import Any

from agent.adapter.data import generate
from agent.adapter.export import gguf_tensor_name, write_lora_gguf
from agent.adapter.hygiene import eval_tasks, held_out_filter
from agent.adapter.prompt import PROMPT_VERSION
from agent.adapter.recipe import Recipe
from agent.adapter.train import (
    TARGET_MODULES,
    answer_loss,
    batches,
    collate,
    encode,
    load_base,
    model_architecture,
    native_bf16,
    schedule,
    step_line,
)
from agent.translate.model_path import resolve_model
from rsl.profile import load_profile

# Set before any run: a common peak rate for fully fine-tuning a model of this size; the LoRA's 3e-4
# would move 100 M weights too far.
FULL_LEARNING_RATE = 5e-5


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    defaults = Recipe()
    parser.add_argument("--out", required=True, help="the exact full-rank adapter GGUF to write")
    parser.add_argument("--steps", type=int, default=defaults.steps)
    parser.add_argument("--lr", type=float, default=FULL_LEARNING_RATE)
    parser.add_argument("--pairs", type=int, default=defaults.pairs)
    parser.add_argument("--time-only", action="store_true", help="train --steps steps, report the step time, "
                                                                  "write nothing but the JSON")
    parser.add_argument("--json", default="bench/results/full_finetune_training.json")
    args = parser.parse_args()

    import torch

    recipe = dataclasses.replace(defaults, steps=args.steps, learning_rate=args.lr, pairs=args.pairs,
                                 threads=os.cpu_count() or 1)
    torch.manual_seed(recipe.seed)
    random.seed(recipe.seed)
    torch.set_num_threads(recipe.threads)
    profile = load_profile()
    base = resolve_model(None)
    started = time.monotonic()
    pairs = generate(profile, recipe.pairs, seed=recipe.seed, exclude=held_out_filter(eval_tasks()))
    tokenizer, model = load_base(base)
    # The frozen rest runs in bfloat16 where the CPU multiplies it natively, as in the LoRA recipe; the
    # trained matrices keep float32 masters and are cast for each product by autocast.
    bf16 = native_bf16("cpu")
    if bf16:
        model = model.to(torch.bfloat16)
    for parameter in model.parameters():
        parameter.requires_grad = False
    trained: dict[str, Any] = {}
    originals: dict[str, Any] = {}
    for name, module in model.named_modules():
        if name.rsplit(".", 1)[-1] in TARGET_MODULES:
            module.weight = torch.nn.Parameter(module.weight.detach().float())
            trained[name] = module.weight
            originals[name] = module.weight.detach().clone()
    model.train()
    examples = encode(tokenizer, pairs)
    plan = batches(examples, recipe.batch, recipe.steps, random.Random(recipe.seed))
    optimizer = torch.optim.AdamW(list(trained.values()), lr=recipe.learning_rate, weight_decay=0.0)
    scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, schedule(recipe))
    pad = tokenizer.pad_token_id if tokenizer.pad_token_id is not None else 0
    weights = sum(p.numel() for p in trained.values())
    print(f"training {weights:,} weights on {len(examples)} pairs, {recipe.steps} steps of {recipe.batch}, "
          f"peak lr {recipe.learning_rate:g}, {recipe.threads} threads", file=sys.stderr, flush=True)
    losses: list[float] = []
    training_started = time.monotonic()
    for step, group in enumerate(plan):
        with torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
            loss = answer_loss(model, *collate(group, pad, "cpu"))
        loss.backward()
        torch.nn.utils.clip_grad_norm_(list(trained.values()), 1.0)
        optimizer.step()
        scheduler.step()
        optimizer.zero_grad(set_to_none=True)
        losses.append(float(loss.detach()))
        if step % 10 == 0 or step + 1 == recipe.steps:
            print(step_line(losses, recipe.steps, time.monotonic() - training_started), file=sys.stderr, flush=True)
    train_seconds = time.monotonic() - training_started
    report: dict[str, Any] = {
        "note": "issue 10 capacity: every projection weight fine-tuned (embeddings and norms frozen), same data, "
                "seed, batches and schedule as the shipped rank-16 LoRA; exported exactly as a full-rank adapter",
        "weights_trained": weights, "pairs": len(pairs), "encoded": len(examples), "steps": recipe.steps,
        "batch": recipe.batch, "peak_learning_rate": recipe.learning_rate, "threads": recipe.threads,
        "seconds_per_step": round(train_seconds / recipe.steps, 3), "train_seconds": round(train_seconds, 1),
        "first_loss": round(sum(losses[:10]) / len(losses[:10]), 4),
        "final_loss": round(sum(losses[-10:]) / len(losses[-10:]), 4),
        "loss_every_50": [round(x, 4) for x in losses[::50]],
        "torch": torch.__version__, "machine": f"{platform.machine()}, {os.cpu_count()} cores",
    }
    if not args.time_only:
        out = Path(args.out)
        tensors = {}
        for name, weight in trained.items():
            delta = (weight.detach() - originals[name]).float()
            a, b = full_rank_factors(delta)
            lora_a = gguf_tensor_name(f"{name}.lora_A.weight")
            tensors[lora_a] = a.numpy()
            tensors[lora_a[:-1] + "b"] = b.numpy()
        # alpha equal to the rank of every factor pair would be needed for a scale of 1, and the ranks differ
        # (256 for k/v, 640 elsewhere); the factors carry rank / alpha instead, with alpha 1.
        write_lora_gguf(out, tensors, alpha=1.0, architecture=model_architecture(base), name=out.stem,
                        metadata={"profile_sha256": profile.digest, "prompt_version": str(PROMPT_VERSION)})
        report["adapter"] = str(out)
        report["adapter_mb"] = round(out.stat().st_size / 1e6, 1)
    report["total_seconds"] = round(time.monotonic() - started, 1)
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")
    print(json.dumps({k: v for k, v in report.items() if k != "loss_every_50"}, indent=1))
    return 0


def full_rank_factors(delta: Any) -> tuple[Any, Any]:
    """(A, B) with B @ A / rank == delta: llama.cpp scales by alpha / rank, and alpha is 1."""
    import torch

    out_features, in_features = delta.shape
    rank = min(out_features, in_features)
    if out_features <= in_features:
        return delta * rank, torch.eye(out_features)
    return torch.eye(in_features), delta * rank


if __name__ == "__main__":
    raise SystemExit(main())
