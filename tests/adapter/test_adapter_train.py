"""CI-sized training run: a few steps on a tiny dataset with the real model, torch and llama.cpp."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from agent.adapter.card import read_card
from agent.adapter.data import generate
from agent.adapter.evaluate import complete, load
from agent.adapter.recipe import Recipe
from agent.adapter.train import TrainingError, check_tokenizer, native_bf16, train_encoded
from rsl.profile import Profile
from tests.adapter.conftest import requires


def test_cli_refuses_bad_numbers_and_reads_a_card(tmp_path: Path) -> None:
    from agent.adapter.card import AdapterCard
    from agent.cli import main

    assert main(["train-adapter", "--steps", "0"]) == 2
    card = AdapterCard(adapter_file="a.gguf", adapter_sha256="0" * 64, base_model_file="b.gguf",
                       base_model_sha256="1" * 64, profile_name="default", profile_sha256="2" * 64,
                       prompt_version=1, data={"pairs": 3}, training={"steps": 1})
    path = card.write(tmp_path / "a.json")
    assert read_card(path) == card
    assert json.loads(path.read_text())["licence"].startswith("The adapter is a derivative of Gemma")


def test_the_frozen_base_runs_in_bfloat16_only_where_the_device_multiplies_it_natively() -> None:
    # An AVX2-only CPU emulates bfloat16 about 150 times slower than float32.
    assert not native_bf16("cpu", "processor\t: 0\nflags\t\t: fpu sse2 avx fma avx2 f16c\n")
    assert native_bf16("cpu", "flags\t\t: fpu avx2 avx512f avx512_bf16\n")
    assert native_bf16("cpu", "flags\t\t: fpu avx2 avx512f amx_bf16 amx_tile\n")
    assert native_bf16("cpu", "Features\t: fp asimd evtstrm bf16 i8mm\n")
    assert not native_bf16("cpu", "")
    assert native_bf16("cuda", "")


class _PiecewiseTokenizer:
    """Splits each word into letters, each a real token of the model's vocabulary, the way transformers 5.17's
    GGUF tokenizer split "lookup" into pieces that llama.cpp never feeds the model."""

    def __init__(self, base_gguf: Path) -> None:
        import llama_cpp

        self.vocab = llama_cpp.Llama(str(base_gguf), vocab_only=True, verbose=False)

    def encode(self, text: str, add_special_tokens: bool = False) -> list[int]:
        ids: list[int] = []
        for char in text:
            ids.extend(self.vocab.tokenize(char.encode(), add_bos=False, special=False))
        return ids


def test_training_refuses_a_tokenizer_that_splits_text_unlike_llama_cpp(profile: Profile, base_gguf: Path) -> None:
    pairs = generate(profile, 8, seed=3)
    with pytest.raises(TrainingError) as refused:
        check_tokenizer(_PiecewiseTokenizer(base_gguf), base_gguf, pairs)
    message = str(refused.value)
    assert "llama.cpp" in message and "transformers" in message
    assert pairs[0].prompt.splitlines()[0][:20] in message  # where: the text that tokenized differently


def test_pairs_encoded_here_train_an_adapter_that_learns_them(profile: Profile, base_gguf: Path,
                                                              tmp_path: Path) -> None:
    # Encoded by the CLI and trained from the IDs, as on a GPU machine whose transformers splits text
    # unlike llama.cpp; `train` runs the same steps after encoding the pairs itself.
    requires("torch", "transformers", "peft", "gguf")
    import llama_cpp

    from agent.adapter.examples import read_examples
    from agent.adapter.hygiene import eval_tasks, held_out_filter
    from agent.adapter.prompt import training_text
    from agent.cli import main

    saved = tmp_path / "examples.json.gz"
    assert main(["train-adapter", "--pairs", "16", "--seed", "5", "--eval", "0", "--save-examples", str(saved)]) == 0
    encoded = read_examples(saved)
    pairs = generate(profile, 16, seed=5, exclude=held_out_filter(eval_tasks()))
    # Each pair as llama.cpp tokenizes it at run time, with the loss on the answer only.
    vocab = llama_cpp.Llama(str(base_gguf), vocab_only=True, verbose=False)
    expected = []
    for pair in pairs:
        prompt_ids, answer_ids = (vocab.tokenize(text.encode(), add_bos=False, special=False)
                                  for text in training_text(pair.prompt, pair.program))
        prompt_ids = [vocab.token_bos(), *prompt_ids]
        answer_ids = [*answer_ids, vocab.token_eos()]
        expected.append((tuple(prompt_ids + answer_ids), tuple([-100] * len(prompt_ids) + answer_ids)))
    assert list(encoded.examples) == expected
    assert encoded.normalized == tuple(p.normalized for p in pairs) and encoded.seed == 5
    assert sum(encoded.groups.values()) == encoded.pairs == 16

    out = tmp_path / "tiny.gguf"
    lines: list[str] = []
    result = train_encoded(encoded.examples, base_gguf, out,
                           Recipe(steps=12, batch=4, learning_rate=1e-3, warmup=2, rank=4, alpha=8, seed=1,
                                  threads=1), progress=lines.append)
    assert result.steps == 12 and result.examples == 16
    # 16 pairs in batches of 4: steps 1-4 and 9-12 see the same pairs, before and after learning them.
    first_epoch, last_epoch = result.losses[:4], result.losses[-4:]
    assert sum(last_epoch) < 0.6 * sum(first_epoch), result.losses
    assert any(line.startswith("step 12/12") and "loss" in line for line in lines)
    assert f"runs in {'bfloat16' if result.bf16 else 'float32'}" in "\n".join(lines)
    assert result.bf16 == native_bf16(result.device)
    assert out.stat().st_size > 0

    prompt = pairs[0].prompt
    plain = complete(load(base_gguf, None, threads=1), prompt, max_tokens=12)
    adapted = complete(load(base_gguf, out, threads=1), prompt, max_tokens=12)
    assert adapted != plain


def test_an_examples_file_for_another_profile_or_a_damaged_one_is_refused(tmp_path: Path,
                                                                          capsys: pytest.CaptureFixture[str]) -> None:
    import dataclasses

    from agent.adapter.card import sha256_of
    from agent.adapter.examples import EncodedExamples
    from agent.adapter.prompt import PROMPT_VERSION
    from agent.cli import main
    from agent.translate.model_path import resolve_model
    from rsl.profile import load_profile

    requires("torch", "transformers", "peft", "gguf")
    fits = EncodedExamples(examples=(((2, 5), (-100, 5)),), base_model_sha256=sha256_of(resolve_model(None)),
                           profile_name="default", profile_sha256=load_profile().digest,
                           prompt_version=PROMPT_VERSION, seed=0, pairs=1, groups={"simple": 1},
                           normalized=("drive forward",), transformers="5.24.0")
    other = dataclasses.replace(fits, profile_sha256="0" * 64).write(tmp_path / "other.json.gz")
    assert main(["train-adapter", "--examples", str(other), "--eval", "0"]) == 1
    assert "another robot profile" in capsys.readouterr().err

    damaged = tmp_path / "damaged.json.gz"
    damaged.write_bytes(fits.write(tmp_path / "fits.json.gz").read_bytes()[:40])
    assert main(["train-adapter", "--examples", str(damaged), "--eval", "0"]) == 1
    assert "cannot read encoded examples" in capsys.readouterr().err

    assert main(["train-adapter", "--examples", str(other), "--dump-data", str(tmp_path / "d.jsonl")]) == 2
    assert not (tmp_path / "d.jsonl").exists()
