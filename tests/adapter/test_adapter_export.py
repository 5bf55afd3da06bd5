"""The LoRA GGUF writer: names, layout, and that llama.cpp loads and applies what it writes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from agent.adapter.evaluate import complete, load
from agent.adapter.export import gguf_tensor_name, write_lora_gguf
from agent.adapter.prompt import adapter_prompt
from rsl.profile import load_profile
from tests.adapter.conftest import requires


def test_peft_names_map_to_llama_cpp_names() -> None:
    assert gguf_tensor_name("base_model.model.model.layers.3.self_attn.q_proj.lora_A.default.weight") == \
        "blk.3.attn_q.weight.lora_a"
    assert gguf_tensor_name("base_model.model.model.layers.17.mlp.down_proj.lora_B.weight") == \
        "blk.17.ffn_down.weight.lora_b"
    with pytest.raises(ValueError, match="cannot map LoRA tensor"):
        gguf_tensor_name("base_model.model.model.embed_tokens.lora_A.weight")


def test_llama_cpp_loads_the_adapter_and_it_changes_the_output(base_gguf: Path, tmp_path: Path) -> None:
    requires("gguf")
    import gguf

    base = load(base_gguf, None, threads=1)
    meta = base.metadata
    width = int(meta["gemma3.embedding_length"])
    shapes = {"attn_q": (int(meta["gemma3.attention.head_count"]) * int(meta["gemma3.attention.key_length"]),
                         width),
              "ffn_up": (int(meta["gemma3.feed_forward_length"]), width)}
    rng = np.random.default_rng(0)
    rank = 4
    tensors = {}
    for layer in range(4):
        for name, (out_features, in_features) in shapes.items():
            tensors[f"blk.{layer}.{name}.weight.lora_a"] = rng.normal(0, 0.5, (rank, in_features))
            tensors[f"blk.{layer}.{name}.weight.lora_b"] = rng.normal(0, 0.5, (out_features, rank))
    path = write_lora_gguf(tmp_path / "noise.gguf", tensors, alpha=8, architecture="gemma3", name="noise",
                           metadata={"profile_sha256": "x"})
    fields = gguf.GGUFReader(str(path)).fields
    assert fields["general.type"].contents() == "adapter"
    assert fields["adapter.type"].contents() == "lora"
    assert fields["adapter.lora.alpha"].contents() == pytest.approx(8)
    assert not list(tmp_path.glob("*.partial"))

    prompt = adapter_prompt("move forward 2 m", load_profile())
    plain = complete(base, prompt, max_tokens=12)
    adapted = complete(load(base_gguf, path, threads=1), prompt, max_tokens=12)
    assert adapted != plain


def test_the_writer_refuses_unpaired_or_misnamed_tensors(tmp_path: Path) -> None:
    requires("gguf")
    a = np.zeros((2, 4))
    with pytest.raises(ValueError, match="has no"):
        write_lora_gguf(tmp_path / "x.gguf", {"blk.0.attn_q.weight.lora_a": a}, alpha=2, architecture="gemma3",
                        name="x")
    with pytest.raises(ValueError, match="is not a LoRA tensor"):
        write_lora_gguf(tmp_path / "x.gguf", {"blk.0.attn_q.weight": a}, alpha=2, architecture="gemma3",
                        name="x")
    assert not (tmp_path / "x.gguf").exists()


@pytest.mark.parametrize("shape", [(256, 640), (2048, 640), (640, 2048)])
def test_a_full_fine_tune_delta_is_exported_exactly_as_full_rank_factors(shape: tuple[int, int]) -> None:
    requires("torch")
    import torch

    from bench.bench_full_finetune import full_rank_factors

    delta = torch.randn(shape, generator=torch.Generator().manual_seed(0)) * 1e-3
    a, b = full_rank_factors(delta)
    rank = min(shape)
    assert a.shape == (rank, shape[1]) and b.shape == (shape[0], rank)
    # llama.cpp adds B @ A scaled by alpha / rank, and the export writes alpha 1.
    torch.testing.assert_close(b @ a / rank, delta)
