"""The RSL adapter: a LoRA adapter that teaches the embedded model RSL.

`prompt` holds the short prompt format the adapter was trained on, and
`card` what an adapter was made for; they are the only parts the runtime
imports. `data` generates training pairs from a robot profile, and
`train`/`export` (the `nrtrans[train]` extra) fit the adapter and write it
as a llama.cpp LoRA GGUF. The runtime never imports torch.
"""
