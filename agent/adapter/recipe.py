"""The training recipe and its defaults, the ones the shipped adapter was trained with.

Kept apart from `agent.adapter.train` so that `nrtrans train-adapter --help` can show the defaults without
importing torch: the command line and the trainer read the same record.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Recipe:
    pairs: int = 20000  # training pairs generated from the profile
    steps: int = 1000
    batch: int = 8
    learning_rate: float = 3e-4
    warmup: int = 20
    rank: int = 16
    alpha: float = 32.0
    seed: int = 0
    threads: int = 0  # 0: every core
    # The frozen base runs in bfloat16 where the device multiplies it natively (about 10x faster on CPUs
    # with AMX or AVX512-BF16; GPUs), else in float32: an AVX2-only CPU emulates bfloat16 about 150x
    # slower than float32. None: choose by the device (`train.native_bf16`); the LoRA weights stay float32.
    bf16: bool | None = None
    # Also write the adapter every this many steps (`<out>.step<N>.gguf`), for a learning curve; 0: never.
    checkpoint_every: int = 0
