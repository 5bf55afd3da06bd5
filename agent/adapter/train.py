"""Fit a LoRA adapter on (task, program) pairs and export it for llama.cpp.

Needs the `nrtrans[train]` extra (torch, transformers, peft, gguf); nothing
in the runtime imports this module. The base model is read straight from
its GGUF file, so training and inference start from the same weights
(dequantized for training).
"""

from __future__ import annotations

import math
import random
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from agent.adapter.data import Pair
from agent.adapter.export import gguf_tensor_name, write_lora_gguf
from agent.adapter.prompt import training_text
from agent.adapter.recipe import Recipe

TARGET_MODULES = ("q_proj", "k_proj", "v_proj", "o_proj", "gate_proj", "up_proj", "down_proj")
MAX_TOKENS = 192
TOKENIZER_SAMPLE = 200  # training pairs whose prompt and answer must tokenize as llama.cpp does
# CPU flags of native bfloat16 matrix products: x86's AMX and AVX512-BF16, Arm's BF16 extension.
_BF16_FLAGS = frozenset({"amx_bf16", "avx512_bf16", "bf16"})


def _to_stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


class TrainingError(RuntimeError):
    """Training cannot start or go on; the message says what to do."""


@dataclass(frozen=True)
class TrainResult:
    adapter: Path
    steps: int
    examples: int
    seconds: float
    device: str
    first_loss: float
    final_loss: float
    losses: tuple[float, ...] = field(repr=False)
    bf16: bool = False  # whether the frozen base ran in bfloat16


def native_bf16(device: str, cpuinfo: str | None = None) -> bool:
    """Whether `device` multiplies bfloat16 matrices natively (`cpuinfo`: /proc/cpuinfo's text).

    Elsewhere torch emulates bfloat16: on an AVX2-only AMD EPYC a product took about 150 times as long
    as in float32, and the CI-sized training test ran for more than 12 minutes instead of about two.
    """
    if device != "cpu":
        return True
    if cpuinfo is None:
        try:
            cpuinfo = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
        except OSError:
            return False
    flags: set[str] = set()
    for line in cpuinfo.splitlines():
        key, _, value = line.partition(":")
        if key.strip() in ("flags", "Features"):
            flags.update(value.split())
    return bool(flags & _BF16_FLAGS)


def require_train_extra() -> None:
    missing = []
    for module in ("torch", "transformers", "peft", "gguf"):
        try:
            __import__(module)
        except ImportError:
            missing.append(module)
    if missing:
        raise TrainingError(
            f"training an adapter needs {', '.join(missing)}, which are not installed.\n"
            "  Install the training extra: pip install 'torch==2.13.0' && pip install 'nrtrans[train]'")


def load_base(gguf_path: Path) -> tuple[Any, Any]:
    """(tokenizer, trainable float32 model) from a GGUF file."""
    from transformers import AutoModelForCausalLM

    directory, name = str(gguf_path.parent), gguf_path.name
    tokenizer = load_tokenizer(gguf_path)
    loaded = AutoModelForCausalLM.from_pretrained(directory, gguf_file=name, dtype="float32")
    # A GGUF-loaded model refuses some operations (save_pretrained); a model
    # rebuilt from its config with the weights copied over behaves normally.
    model = type(loaded)(loaded.config)
    missing, unexpected = model.load_state_dict(loaded.state_dict(), strict=False)
    real_missing = [k for k in missing if "lm_head" not in k]
    if real_missing or unexpected:
        raise TrainingError(f"weights from {gguf_path} do not fit the model rebuilt from its config: "
                            f"missing {real_missing[:3]}, unexpected {unexpected[:3]}")
    model.tie_weights()
    return tokenizer, model


def load_tokenizer(gguf_path: Path) -> Any:
    """The tokenizer transformers builds from a GGUF file (check it with `check_tokenizer` before use)."""
    from transformers import AutoTokenizer

    return AutoTokenizer.from_pretrained(str(gguf_path.parent), gguf_file=gguf_path.name)


def encode(tokenizer: Any, pairs: Sequence[Pair]) -> list[tuple[list[int], list[int]]]:
    """(input ids, labels) per pair; the prompt is masked so the loss is on the answer only.

    Prompt and answer are tokenized apart, as llama.cpp sees them at run time:
    the prompt is evaluated, then the answer is generated token by token.
    """
    bos = tokenizer.bos_token_id
    eos = tokenizer.eos_token_id
    out = []
    for pair in pairs:
        prompt, answer = training_text(pair.prompt, pair.program)
        prompt_ids = [bos, *tokenizer.encode(prompt, add_special_tokens=False)]
        answer_ids = [*tokenizer.encode(answer, add_special_tokens=False), eos]
        ids = prompt_ids + answer_ids
        if len(ids) > MAX_TOKENS:
            continue
        out.append((ids, [-100] * len(prompt_ids) + answer_ids))
    return out


def encode_checked(tokenizer: Any, base_gguf: Path, pairs: Sequence[Pair]) -> list[tuple[list[int], list[int]]]:
    """`encode`, after `check_tokenizer` has found the tokenizer splitting text as llama.cpp does."""
    check_tokenizer(tokenizer, base_gguf, pairs[:TOKENIZER_SAMPLE])
    return encode(tokenizer, pairs)


def check_tokenizer(tokenizer: Any, base_gguf: Path, pairs: Sequence[Pair]) -> None:
    """Refuse to train when the tokenizer transformers builds from the GGUF splits text unlike llama.cpp.

    The adapter learns the token sequences it is trained on, and llama.cpp feeds it its own at run time.
    transformers 5.17 split "lookup" into three pieces where llama.cpp has one; an adapter trained
    that way lost 18 of the suite's 108 tasks while its loss fell as usual.
    """
    import llama_cpp

    vocab = llama_cpp.Llama(str(base_gguf), vocab_only=True, verbose=False)
    for pair in pairs:
        for text in training_text(pair.prompt, pair.program):
            ours = tokenizer.encode(text, add_special_tokens=False)
            theirs = vocab.tokenize(text.encode("utf-8"), add_bos=False, special=False)
            if list(ours) != list(theirs):
                version = getattr(sys.modules.get("transformers"), "__version__", "(version unknown)")
                raise TrainingError(
                    f"the tokenizer transformers {version} builds from {base_gguf.name} splits "
                    f"text unlike llama.cpp, which runs the adapter:\n"
                    f"  text:      {text!r}\n"
                    f"  training:  {len(ours)} tokens {list(ours)[:12]}\n"
                    f"  llama.cpp: {len(theirs)} tokens {list(theirs)[:12]}\n"
                    "  An adapter trained on these tokens would not work. Install a transformers whose GGUF "
                    "tokenizer agrees (5.24 does) and train again.")


def batches(examples: list[tuple[list[int], list[int]]], batch: int, steps: int,
            rng: random.Random) -> list[list[tuple[list[int], list[int]]]]:
    """`steps` batches; similar lengths are grouped so little compute goes to padding."""
    out: list[list[tuple[list[int], list[int]]]] = []
    while len(out) < steps:
        order = examples[:]
        rng.shuffle(order)
        chunk = batch * 16
        epoch: list[list[tuple[list[int], list[int]]]] = []
        for start in range(0, len(order), chunk):
            group = sorted(order[start:start + chunk], key=lambda e: len(e[0]))
            epoch.extend(group[i:i + batch] for i in range(0, len(group), batch))
        rng.shuffle(epoch)
        out.extend(b for b in epoch if len(b) == batch or len(examples) < batch)
    return out[:steps]


def train(pairs: Sequence[Pair], base_gguf: Path, out: Path, recipe: Recipe, *,
          metadata: dict[str, str] | None = None,
          progress: Callable[[str], None] = _to_stderr) -> TrainResult:
    """Train a LoRA adapter on `pairs` and write it to `out` as a llama.cpp LoRA GGUF."""
    return _fit(lambda tokenizer: encode_checked(tokenizer, base_gguf, pairs), base_gguf, out, recipe, metadata,
                progress)


def train_encoded(examples: Sequence[tuple[Sequence[int], Sequence[int]]], base_gguf: Path, out: Path,
                  recipe: Recipe, *, metadata: dict[str, str] | None = None,
                  progress: Callable[[str], None] = _to_stderr) -> TrainResult:
    """Train as `train` does, from pairs encoded already where the tokenizer agreed with llama.cpp
    (`agent.adapter.examples`), so this machine's tokenizer is never used."""
    encoded = [(list(ids), list(labels)) for ids, labels in examples]
    return _fit(lambda _tokenizer: encoded, base_gguf, out, recipe, metadata, progress)


def _fit(examples_for: Callable[[Any], list[tuple[list[int], list[int]]]], base_gguf: Path, out: Path,
         recipe: Recipe, metadata: dict[str, str] | None, progress: Callable[[str], None]) -> TrainResult:
    require_train_extra()
    import torch

    random.seed(recipe.seed)
    torch.manual_seed(recipe.seed)
    if recipe.threads:
        torch.set_num_threads(recipe.threads)
    device = "cuda" if torch.cuda.is_available() else "cpu"

    progress(f"loading base model {base_gguf.name} ...")
    tokenizer, model, bf16 = lora_model(base_gguf, recipe, device)
    progress(f"the frozen base runs in {'bfloat16' if bf16 else 'float32'} on {device}")
    examples = examples_for(tokenizer)
    if not examples:
        raise TrainingError("no training pair fits in the token budget; generate more or shorter pairs")
    plan = batches(examples, recipe.batch, recipe.steps, random.Random(recipe.seed))
    trainable = [p for p in model.parameters() if p.requires_grad]
    optimizer = torch.optim.AdamW(trainable, lr=recipe.learning_rate, weight_decay=0.0)

    scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, schedule(recipe))
    pad = tokenizer.pad_token_id if tokenizer.pad_token_id is not None else 0
    losses: list[float] = []
    started = time.monotonic()
    progress(f"training {sum(p.numel() for p in trainable):,} LoRA weights on {len(examples)} pairs, "
             f"{recipe.steps} steps of {recipe.batch}, on {device}")
    for step, group in enumerate(plan):
        loss = answer_loss(model, *collate(group, pad, device))
        loss.backward()
        torch.nn.utils.clip_grad_norm_(trainable, 1.0)
        optimizer.step()
        scheduler.step()
        optimizer.zero_grad(set_to_none=True)
        losses.append(float(loss.detach()))
        if recipe.checkpoint_every and (step + 1) % recipe.checkpoint_every == 0 and step + 1 < recipe.steps:
            checkpoint = out.with_name(f"{out.stem}.step{step + 1}{out.suffix}")
            _write(model, checkpoint, recipe, base_gguf, metadata)
            progress(f"wrote checkpoint {checkpoint}")
        if step % 10 == 0 or step + 1 == recipe.steps:
            progress(step_line(losses, recipe.steps, time.monotonic() - started))
    seconds = time.monotonic() - started

    _write(model, out, recipe, base_gguf, metadata)
    progress(f"wrote {out} ({out.stat().st_size / 1e6:.1f} MB) after {seconds / 60:.1f} min")
    head = losses[:10]
    tail = losses[-10:]
    return TrainResult(adapter=out, steps=len(plan), examples=len(examples), seconds=seconds, device=device,
                       first_loss=sum(head) / len(head), final_loss=sum(tail) / len(tail),
                       losses=tuple(losses), bf16=bf16)


def lora_model(base_gguf: Path, recipe: Recipe, device: str) -> tuple[Any, Any, bool]:
    """(tokenizer, the base with `recipe`'s LoRA weights in training mode, whether the base runs in bfloat16)."""
    import torch
    from peft import LoraConfig, get_peft_model

    tokenizer, model = load_base(base_gguf)
    bf16 = native_bf16(device) if recipe.bf16 is None else recipe.bf16
    if bf16:
        model = model.to(torch.bfloat16)
    config = LoraConfig(r=recipe.rank, lora_alpha=int(recipe.alpha), lora_dropout=0.0,
                        target_modules=list(TARGET_MODULES), bias="none", task_type="CAUSAL_LM")
    model = get_peft_model(model, config).to(device)
    model.train()
    return tokenizer, model, bf16


def schedule(recipe: Recipe) -> Callable[[int], float]:
    """The learning-rate factor per step: linear warm-up, then cosine decay to 10%."""
    def rate(step: int) -> float:
        if step < recipe.warmup:
            return (step + 1) / recipe.warmup
        done = (step - recipe.warmup) / max(1, recipe.steps - recipe.warmup)
        return 0.1 + 0.9 * 0.5 * (1 + math.cos(math.pi * done))
    return rate


def step_line(losses: Sequence[float], steps: int, elapsed: float) -> str:
    """The progress line after `len(losses)` of `steps` steps: the running loss, the pace and the ETA."""
    done = len(losses)
    recent = losses[-10:]
    return (f"step {done}/{steps}  loss {sum(recent) / len(recent):.4f}  {elapsed / done:.2f} s/step  "
            f"eta {elapsed / done * (steps - done) / 60:.1f} min")


def collate(group: list[tuple[list[int], list[int]]], pad: int, device: str) -> tuple[Any, Any, Any]:
    """(input ids, attention mask, labels) of a batch, right-padded to its longest example."""
    import torch

    width = max(len(ids) for ids, _ in group)
    input_ids = torch.tensor([ids + [pad] * (width - len(ids)) for ids, _ in group], device=device)
    mask = torch.tensor([[1] * len(ids) + [0] * (width - len(ids)) for ids, _ in group], device=device)
    labels = torch.tensor([lab + [-100] * (width - len(lab)) for _, lab in group], device=device)
    return input_ids, mask, labels


def _write(model: Any, out: Path, recipe: Recipe, base_gguf: Path, metadata: dict[str, str] | None) -> None:
    tensors = {gguf_tensor_name(name): param.detach().float().cpu().numpy()
               for name, param in model.named_parameters() if "lora_" in name}
    write_lora_gguf(out, tensors, alpha=recipe.alpha, architecture=model_architecture(base_gguf),
                    name=out.stem, metadata=metadata)


def answer_loss(model: Any, input_ids: Any, mask: Any, labels: Any) -> Any:
    """Cross-entropy on the answer tokens only.

    The output layer of a 262k-token vocabulary dominates the cost of a step,
    so logits are computed only where a label is, not at every position.
    """
    import torch

    # A LoRA model wraps the causal LM; a fully fine-tuned one is the causal LM.
    causal_lm = model.get_base_model() if hasattr(model, "get_base_model") else model
    hidden = causal_lm.model(input_ids=input_ids, attention_mask=mask).last_hidden_state
    targets = labels[:, 1:]
    where = targets != -100
    logits = causal_lm.lm_head(hidden[:, :-1][where])
    cap = getattr(causal_lm.config, "final_logit_softcapping", None)
    if cap:
        logits = torch.tanh(logits / cap) * cap
    return torch.nn.functional.cross_entropy(logits.float(), targets[where])


def model_architecture(gguf_path: Path) -> str:
    import gguf

    reader = gguf.GGUFReader(str(gguf_path))
    field_ = reader.fields.get("general.architecture")
    if field_ is None:
        raise TrainingError(f"{gguf_path} has no general.architecture; is it a GGUF model file?")
    return str(field_.contents())
