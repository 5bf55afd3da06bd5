"""Write LoRA weights as a llama.cpp LoRA adapter GGUF.

The layout follows llama.cpp's own converter (convert_lora_to_gguf.py):
`general.type = adapter`, `adapter.type = lora`, `adapter.lora.alpha`, and
for every adapted base tensor `<base name>.lora_a` with torch shape
(rank, in) and `<base name>.lora_b` with shape (out, rank), where the base name
is the tensor's name in the base model's GGUF (`blk.3.attn_q.weight`). Only
numpy and the `gguf` package are needed here.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

# Hugging Face module names -> llama.cpp tensor names, for Gemma-style decoders.
HF_TO_GGUF = {
    "self_attn.q_proj": "attn_q",
    "self_attn.k_proj": "attn_k",
    "self_attn.v_proj": "attn_v",
    "self_attn.o_proj": "attn_output",
    "mlp.gate_proj": "ffn_gate",
    "mlp.up_proj": "ffn_up",
    "mlp.down_proj": "ffn_down",
}

_PEFT_NAME = re.compile(r"(?:.*\.)?layers\.(\d+)\.(\w+\.\w+)\.lora_([AB])(?:\.\w+)?\.weight\Z")


def gguf_tensor_name(peft_name: str) -> str:
    """`...layers.3.self_attn.q_proj.lora_A.default.weight` -> `blk.3.attn_q.weight.lora_a`."""
    match = _PEFT_NAME.match(peft_name)
    if match is None or match.group(2) not in HF_TO_GGUF:
        raise ValueError(f"cannot map LoRA tensor {peft_name!r} to a llama.cpp tensor name; "
                         f"adapt only {', '.join(sorted(HF_TO_GGUF))}")
    layer, module, side = match.groups()
    return f"blk.{layer}.{HF_TO_GGUF[module]}.weight.lora_{side.lower()}"


def write_lora_gguf(path: Path, tensors: Mapping[str, np.ndarray], *, alpha: float, architecture: str,
                    name: str, metadata: Mapping[str, str] | None = None) -> Path:
    """Write `tensors` (llama.cpp names -> arrays) as an f16 LoRA adapter GGUF at `path`."""
    import gguf

    if not tensors:
        raise ValueError("no LoRA tensors to write")
    for key in tensors:
        if not (key.endswith(".lora_a") or key.endswith(".lora_b")):
            raise ValueError(f"tensor {key!r} is not a LoRA tensor (it must end in .lora_a or .lora_b)")
        partner = key[:-1] + ("b" if key.endswith("a") else "a")
        if partner not in tensors:
            raise ValueError(f"LoRA tensor {key!r} has no {partner!r}")
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".partial")
    writer = gguf.GGUFWriter(str(partial), architecture)
    writer.add_type(gguf.GGUFType.ADAPTER)
    writer.add_string(gguf.Keys.Adapter.TYPE, "lora")
    writer.add_float32(gguf.Keys.Adapter.LORA_ALPHA, float(alpha))
    writer.add_name(name)
    for key, value in (metadata or {}).items():
        writer.add_string(f"nrtrans.{key}", value)
    for key in sorted(tensors):
        writer.add_tensor(key, np.ascontiguousarray(tensors[key], dtype=np.float16))
    writer.write_header_to_file()
    writer.write_kv_data_to_file()
    writer.write_tensors_to_file()
    writer.close()
    # Written under another name and renamed, so a crash never leaves a torn adapter.
    partial.replace(path)
    return path
