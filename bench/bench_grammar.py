"""Grammar overhead: constrained vs unconstrained token rate, same model, same prompts, side by side.

Three decoders run interleaved on each prompt so machine load hits them alike:
  free        greedy decoding with no grammar (nrtrans's own loop)
  masked      greedy decoding under the RSL automaton's precomputed token masks (what nrtrans uses)
  gbnf        llama.cpp's GBNF sampler via create_completion, with its own unconstrained run as reference
Writes bench/results/grammar.json.

    python bench/bench_grammar.py [--model PATH] [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

from agent.normalize import normalize_task
from agent.translate import Translator
from agent.translate.automaton import RslAutomaton
from rsl.grammar import to_gbnf
from rsl.profile import load_profile

TASKS = ["move forward two meters then turn left ninety degrees", "look around", "grasp the cup",
         "go to 2, -1 then perceive", "back up half a meter"]
TOKENS = 24


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--model", help="GGUF model (default: the embedded Gemma 3 270M)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", default="bench/results/grammar.json")
    args = parser.parse_args()

    from llama_cpp import LlamaGrammar

    profile = load_profile()
    translator = Translator.load(profile, model=args.model, adapter="none")
    engine = translator.engine
    llm = engine.llm  # type: ignore[attr-defined]
    automaton = RslAutomaton(profile)
    gbnf = LlamaGrammar.from_string(to_gbnf(profile), verbose=False)
    prompts = [translator.prompt_for(normalize_task(t)) for t in TASKS]
    for prompt in prompts:  # warm the KV prefix and the token masks
        engine.generate(prompt, automaton, TOKENS)
    rates: dict[str, list[float]] = {"free": [], "masked": [], "gbnf": [], "gbnf_free": []}
    for repeat in range(args.repeats):
        for prompt in prompts:
            for name, mask in (("free", None), ("masked", automaton)):
                out = engine.generate(prompt, mask, TOKENS)
                if out.generated_tokens:
                    rates[name].append(out.generated_tokens / (out.generate_ms / 1000))
            for name, grammar in (("gbnf_free", None), ("gbnf", gbnf)):
                engine.generate(prompt, None, 1)  # same KV prefix state for both
                first = None
                count = 0
                for _chunk in llm.create_completion(prompt, max_tokens=TOKENS, temperature=0.0, top_k=1,
                                                    grammar=grammar, stream=True):
                    count += 1
                    if first is None:
                        first = time.perf_counter()
                if first is not None and count > 1:
                    rates[name].append((count - 1) / (time.perf_counter() - first))
        print(f"repeat {repeat + 1}/{args.repeats}: " + ", ".join(
            f"{k} {statistics.median(v):.1f} tok/s" for k, v in rates.items() if v), file=sys.stderr)
    medians = {k: statistics.median(v) for k, v in rates.items() if v}
    report = {
        "model": translator.model_name,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the end",
        "tokens_per_prompt": TOKENS,
        "samples": {k: len(v) for k, v in rates.items()},
        "median_tokens_per_s": {k: round(v, 2) for k, v in medians.items()},
        "ratio_masked_vs_free": round(medians["masked"] / medians["free"], 3),
        "ratio_gbnf_vs_free": round(medians["gbnf"] / medians["gbnf_free"], 3),
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    print(json.dumps(report, indent=2))
    translator.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
