"""How long one step of the shipped LoRA recipe takes on this machine, and where the time goes.

Issue 10 asks for a retrain of at most 45 minutes on 2 cores. The recipe's
time is its steps times the time of one step, so this runs the first steps
of the recipe itself (the same pairs, seed, batches, rank and precision
choice as `nrtrans train-adapter`) and times each, then profiles one step
to say how much of it is matrix products: when that share is high, the step
is bound by the CPU's multiply rate and only fewer or shorter examples make
it faster.

    python bench/bench_train_step.py [--steps 20] [--out bench/results/train_step.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from agent.adapter.data import generate
from agent.adapter.recipe import Recipe
from agent.adapter.train import answer_loss, batches, collate, encode, lora_model, require_train_extra
from agent.translate.model_path import resolve_model
from rsl.profile import load_profile

# A few steps first: the first products of each shape are slower while the libraries set up.
WARMUP = 2
# Products, the share of a step that grows with the CPU's multiply rate.
PRODUCTS = ("aten::mm", "aten::bmm", "aten::addmm")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=20, help="recipe steps to time after the warm-up (default 20)")
    parser.add_argument("--out", default="bench/results/train_step.json", help="where the JSON figures go")
    args = parser.parse_args()
    if args.steps < 1:
        parser.error("--steps must be at least 1")
    require_train_extra()
    import torch
    from torch.profiler import ProfilerActivity, profile

    recipe = Recipe()
    random.seed(recipe.seed)
    torch.manual_seed(recipe.seed)
    device = "cuda" if torch.cuda.is_available() else "cpu"
    print("loading the base model and generating the recipe's pairs ...", file=sys.stderr, flush=True)
    tokenizer, model, bf16 = lora_model(resolve_model(None), recipe, device)
    examples = encode(tokenizer, generate(load_profile(), recipe.pairs, seed=recipe.seed))
    plan = batches(examples, recipe.batch, WARMUP + args.steps + 1, random.Random(recipe.seed))
    trainable = [p for p in model.parameters() if p.requires_grad]
    optimizer = torch.optim.AdamW(trainable, lr=recipe.learning_rate, weight_decay=0.0)
    pad = tokenizer.pad_token_id if tokenizer.pad_token_id is not None else 0

    def step(group: list[tuple[list[int], list[int]]]) -> None:
        answer_loss(model, *collate(group, pad, device)).backward()
        torch.nn.utils.clip_grad_norm_(trainable, 1.0)
        optimizer.step()
        optimizer.zero_grad(set_to_none=True)

    seconds, tokens = [], []
    for index, group in enumerate(plan[:-1]):
        started = time.perf_counter()
        step(group)
        if index >= WARMUP:
            seconds.append(time.perf_counter() - started)
            tokens.append(len(group) * max(len(ids) for ids, _ in group))
            print(f"step {index + 1 - WARMUP}/{args.steps}: {seconds[-1]:.2f} s, {tokens[-1]} tokens",
                  file=sys.stderr, flush=True)
    with profile(activities=[ProfilerActivity.CPU]) as profiled:
        step(plan[-1])
    events = profiled.key_averages()
    total = sum(e.self_cpu_time_total for e in events)
    products = sum(e.self_cpu_time_total for e in events if e.key in PRODUCTS)
    mean = statistics.fmean(seconds)
    figures = {
        "steps_timed": len(seconds),
        "step_s_p50": round(statistics.median(seconds), 3),
        "step_s_mean": round(mean, 3),
        "step_s_min": round(min(seconds), 3),
        "step_s_max": round(max(seconds), 3),
        "tokens_per_step_p50": statistics.median(tokens),
        "products_share_of_a_step": round(products / total, 3) if total else None,
        # A retrain is the sum of its steps, so the mean (not the median) times the step count.
        "retrain_min_estimate": round(mean * recipe.steps / 60, 1),
        "recipe": {"steps": recipe.steps, "batch": recipe.batch, "rank": recipe.rank, "pairs": recipe.pairs},
        "bf16_base": bf16,
        "device": device,
        "threads": torch.get_num_threads(),
        "machine": {"cpus": os.cpu_count(), "processor": _cpu_name(), "python": platform.python_version(),
                    "torch": torch.__version__, "load_avg": list(os.getloadavg())},
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(figures, indent=1) + "\n", encoding="utf-8")
    print(json.dumps(figures, indent=1))
    return 0


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


if __name__ == "__main__":
    raise SystemExit(main())
