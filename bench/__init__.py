"""Benchmarks; each writes its figures as JSON under bench/results/."""

# What a bench's `--split` asks of `Translator.load(split_clauses=...)`: None keeps the translator's default.
SPLIT = {"default": None, "on": True, "off": False}
