"""Score an adapter on held-out synthetic pairs with llama.cpp.

Two ways: the adapter alone (each pair's prompt decoded greedily, optionally
under the profile's GBNF grammar, until the blank line that ends a program),
and as the runtime runs it (the raw task through the `Translator`). A pair
counts as exact (same canonical text) and accepted (compiles, and the plan
matches with numbers within `TOLERANCE`).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from agent.adapter.data import Pair
from rsl.compiler import compile_program
from rsl.plan import Plan, Quantity
from rsl.profile import Profile

TOLERANCE = 0.02
MAX_TOKENS = 200


@dataclass(frozen=True)
class Score:
    total: int
    exact: int
    accepted: int
    by_group: dict[str, tuple[int, int]]  # group -> (accepted, total)
    latency_p50_ms: float
    failures: tuple[tuple[str, str, str], ...] = field(repr=False)  # (task, expected, got)

    def to_dict(self) -> dict[str, Any]:
        return {
            "pairs": self.total,
            "exact": round(self.exact / self.total, 4) if self.total else 0.0,
            "accepted": round(self.accepted / self.total, 4) if self.total else 0.0,
            "groups": {g: round(a / t, 4) for g, (a, t) in sorted(self.by_group.items())},
            "latency_p50_ms": round(self.latency_p50_ms, 1),
        }


def same_plan(a: Plan, b: Plan, tolerance: float = TOLERANCE) -> bool:
    if len(a) != len(b):
        return False
    for x, y in zip(a, b, strict=True):
        if x.skill != y.skill or len(x.args) != len(y.args):
            return False
        for u, v in zip(x.args, y.args, strict=True):
            if isinstance(u, Quantity) and isinstance(v, Quantity):
                if abs(u.value - v.value) > tolerance:
                    return False
            elif u != v:
                return False
    return True


def load(model: Path, adapter: Path | None, threads: int | None = None) -> Any:
    from agent.translate.engine import open_llama

    return open_llama(model, n_ctx=512, lora_path=adapter, n_threads=threads)


def complete(llm: Any, prompt: str, grammar: Any = None, max_tokens: int = MAX_TOKENS) -> str:
    out = llm.create_completion(prompt, max_tokens=max_tokens, temperature=0.0, top_k=1, stop=["\n\n"],
                                grammar=grammar)
    return str(out["choices"][0]["text"])


def evaluate(llm: Any, pairs: Sequence[Pair], profile: Profile, *, grammar: bool = False,
             progress: Callable[[int, int], None] | None = None) -> Score:
    """The adapter alone: each pair's whole task prompted once, greedy, no repair."""
    gbnf = None
    if grammar:
        from llama_cpp import LlamaGrammar

        from rsl.grammar import to_gbnf

        gbnf = LlamaGrammar.from_string(to_gbnf(profile), verbose=False)

    def write(pair: Pair) -> str:
        # A program has fewer tokens than characters; a runaway answer is cut there, not at MAX_TOKENS.
        return complete(llm, pair.prompt, gbnf, max_tokens=len(pair.program) + 16)

    return _score(pairs, profile, write, progress)


def evaluate_translator(translator: Any, pairs: Sequence[Pair], profile: Profile, *,
                        progress: Callable[[int, int], None] | None = None) -> Score:
    """As the runtime runs it: the raw task through `Translator` (clauses, grammar, repair)."""
    return _score(pairs, profile, lambda pair: str(translator.translate(pair.task).program), progress)


def _score(pairs: Sequence[Pair], profile: Profile, write: Callable[[Pair], str],
           progress: Callable[[int, int], None] | None) -> Score:
    exact = accepted = 0
    groups: dict[str, list[int]] = {}
    latencies = []
    failures = []
    for index, pair in enumerate(pairs):
        started = time.perf_counter()
        text = write(pair)
        latencies.append((time.perf_counter() - started) * 1000)
        got = "".join(line.strip() + "\n" for line in text.splitlines() if line.strip())
        want = compile_program(pair.program, profile).plan
        result = compile_program(got, profile)
        ok = result.ok and want is not None and result.plan is not None and same_plan(result.plan, want)
        exact += got == pair.program
        accepted += ok
        tally = groups.setdefault(pair.group, [0, 0])
        tally[0] += ok
        tally[1] += 1
        if not ok:
            failures.append((pair.normalized, pair.program, got))
        if progress is not None:
            progress(index + 1, len(pairs))
    return Score(total=len(pairs), exact=exact, accepted=accepted,
                 by_group={g: (a, t) for g, (a, t) in groups.items()},
                 latency_p50_ms=statistics.median(latencies) if latencies else 0.0,
                 failures=tuple(failures))
