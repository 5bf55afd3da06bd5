"""Word error rate: how the speech benchmark and tests score a transcript."""

from __future__ import annotations


def word_errors(reference: str, hypothesis: str) -> int:
    """Substitutions + deletions + insertions between two word sequences."""
    ref = reference.split()
    hyp = hypothesis.split()
    previous = list(range(len(hyp) + 1))
    for i, ref_word in enumerate(ref, start=1):
        current = [i] + [0] * len(hyp)
        for j, hyp_word in enumerate(hyp, start=1):
            current[j] = min(previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (ref_word != hyp_word))
        previous = current
    return previous[-1]


def word_error_rate(references: list[str], hypotheses: list[str]) -> float:
    """Total word errors over total reference words, across a corpus."""
    if len(references) != len(hypotheses):
        raise ValueError(f"{len(references)} references but {len(hypotheses)} hypotheses")
    words = sum(len(r.split()) for r in references)
    if words == 0:
        return 0.0
    return sum(word_errors(r, h) for r, h in zip(references, hypotheses, strict=True)) / words
