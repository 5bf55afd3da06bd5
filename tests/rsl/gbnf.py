"""A small, independent reader of the GBNF subset that `rsl.grammar` writes.

The tests use it to draw random programs from the exported grammar and to
turn the grammar into a regular expression, so they check the grammar text
itself rather than trusting the code that produced it.
"""

from __future__ import annotations

import random
import re
from dataclasses import dataclass

# ("alt", [seq]) | ("seq", [node]) | ("lit", s) | ("class", s) | ("ref", name) | ("rep", node, lo, hi)
Node = tuple


@dataclass
class Grammar:
    rules: dict[str, Node]

    def sample(self, rng: random.Random, rule: str = "root", max_repeat: int = 6) -> str:
        out: list[str] = []
        self._sample(self.rules[rule], rng, out, max_repeat)
        return "".join(out)

    def _sample(self, node: Node, rng: random.Random, out: list[str], cap: int) -> None:
        kind = node[0]
        if kind == "alt":
            self._sample(rng.choice(node[1]), rng, out, cap)
        elif kind == "seq":
            for item in node[1]:
                self._sample(item, rng, out, cap)
        elif kind == "lit":
            out.append(node[1])
        elif kind == "class":
            out.append(rng.choice(_expand_class(node[1])))
        elif kind == "ref":
            self._sample(self.rules[node[1]], rng, out, cap)
        elif kind == "rep":
            _, inner, lo, hi = node
            for _ in range(rng.randint(lo, min(hi, max(lo, cap)))):
                self._sample(inner, rng, out, cap)

    def regex(self, rule: str = "root") -> re.Pattern[str]:
        return re.compile(self._regex(self.rules[rule]), re.DOTALL)

    def _regex(self, node: Node) -> str:
        kind = node[0]
        if kind == "alt":
            return "(?:" + "|".join(self._regex(n) for n in node[1]) + ")"
        if kind == "seq":
            return "".join(self._regex(n) for n in node[1])
        if kind == "lit":
            return re.escape(node[1])
        if kind == "class":
            return "[" + node[1] + "]"
        if kind == "ref":
            return "(?:" + self._regex(self.rules[node[1]]) + ")"
        _, inner, lo, hi = node
        return "(?:" + self._regex(inner) + f"){{{lo},{hi}}}"


def _expand_class(body: str) -> list[str]:
    chars: list[str] = []
    i = 0
    while i < len(body):
        if i + 2 < len(body) and body[i + 1] == "-":
            chars.extend(chr(c) for c in range(ord(body[i]), ord(body[i + 2]) + 1))
            i += 3
        else:
            chars.append(body[i])
            i += 1
    return chars


_TOKEN = re.compile(r'\s*(?:(?P<lit>"(?:[^"\\]|\\.)*")|(?P<cls>\[[^\]]*\])|(?P<name>[a-zA-Z0-9-]+)'
                    r'|(?P<rep>\{\d+,\d+\})|(?P<op>[()|?*+]))')


def parse(text: str) -> Grammar:
    rules: dict[str, Node] = {}
    for line in text.strip().splitlines():
        name, _, body = line.partition("::=")
        tokens = [(m.lastgroup, m.group(m.lastgroup)) for m in _TOKEN.finditer(body) if m.lastgroup]
        node, rest = _alternation(tokens)
        assert not rest, f"unparsed: {rest}"
        rules[name.strip()] = node
    return Grammar(rules)


def _alternation(tokens: list) -> tuple[Node, list]:
    options = []
    seq, tokens = _sequence(tokens)
    options.append(seq)
    while tokens and tokens[0] == ("op", "|"):
        seq, tokens = _sequence(tokens[1:])
        options.append(seq)
    return ("alt", options), tokens


def _sequence(tokens: list) -> tuple[Node, list]:
    items: list[Node] = []
    while tokens and tokens[0] not in (("op", "|"), ("op", ")")):
        kind, value = tokens[0]
        tokens = tokens[1:]
        if kind == "lit":
            node: Node = ("lit", value[1:-1].encode().decode("unicode_escape"))
        elif kind == "cls":
            node = ("class", value[1:-1])
        elif kind == "name":
            node = ("ref", value)
        elif value == "(":
            node, tokens = _alternation(tokens)
            assert tokens[0] == ("op", ")")
            tokens = tokens[1:]
        else:
            raise AssertionError(f"unexpected {value}")
        while tokens and (tokens[0][0] == "rep" or tokens[0] in (("op", "?"), ("op", "*"), ("op", "+"))):
            op = tokens[0][1]
            tokens = tokens[1:]
            lo, hi = {"?": (0, 1), "*": (0, 99), "+": (1, 99)}.get(op, (0, 0))
            if op.startswith("{"):
                lo, hi = (int(x) for x in op[1:-1].split(","))
            node = ("rep", node, lo, hi)
        items.append(node)
    return ("seq", items), tokens
