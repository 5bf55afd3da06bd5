"""Running a GGUF model in-process with llama.cpp: greedy decoding, masked by the RSL automaton.

The mask for each automaton state (which tokens may come next, and the state
each one leads to) is found once by walking a trie of the vocabulary through
the automaton, then cached. Sampling a token is then an argmax over a few
hundred logits, so the grammar costs almost nothing per token, unlike
llama.cpp's GBNF sampler that checks all 262k Gemma tokens every step.
"""

from __future__ import annotations

import ctypes
import os
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from agent.translate.automaton import ALPHABET, END, RslAutomaton, State

_OPEN_LOCK = threading.Lock()
# How often a generation looks at its caller's cancel flag while llama.cpp computes.
_CANCEL_POLL_S = 0.01


class CancelFlag(Protocol):
    """Anything with `is_set()`: a `threading.Event`, the robot's `CancelToken`."""

    def is_set(self) -> bool: ...


class GenerationCancelled(Exception):
    """The caller's cancel flag was set while the model was generating."""


@dataclass(frozen=True)
class Generation:
    text: str
    prompt_tokens: int
    reused_tokens: int
    generated_tokens: int
    prompt_ms: float
    generate_ms: float
    finished: bool  # False when the token cap cut it off
    # What the model would write first with no grammar, and how sure it is (softmax over the whole
    # vocabulary): a clause the model does not read as a robot task shows in these.
    first_piece: str = ""
    first_probability: float | None = None  # None: this engine cannot tell
    # Each chosen token's probability among the tokens the grammar allowed there; empty: cannot tell.
    token_probabilities: tuple[float, ...] = ()
    # Where the model could have ended the program but went on: (statements written so far, how many
    # tokens were chosen before that point, the probability it gave to ending there).
    endings: tuple[tuple[int, int, float], ...] = ()
    # The tokens chosen, and where the grammar's runner-up was likely (at least FORK_RECORD_FLOOR): (how
    # many tokens were chosen before that point, the runner-up, its probability). A Fork starts there.
    tokens: tuple[int, ...] = ()
    forks: tuple[tuple[int, int, float], ...] = ()


@dataclass(frozen=True)
class Fork:
    """Generate again from a place in an earlier generation, taking another token there: the tokens
    chosen before it and their probabilities (kept for the model's signal), then `token`."""
    tokens: tuple[int, ...]
    probabilities: tuple[float, ...]
    token: int


# Runner-ups less likely than this are not worth a generation, so they are not recorded.
FORK_RECORD_FLOOR = 0.05


def use_plain_cpu_buffers() -> None:
    """Make every later `llama_cpp.Llama` in this process load plain CPU weight buffers.

    llama.cpp's repacked CPU weight buffers (AMX on this class of Xeon) crash
    in decode, so nrtrans loads models without them; for a model this small
    the plain buffers are as fast. Processes that only serve a model (the
    loopback llama_cpp.server in the tests) call this before loading.
    """
    import llama_cpp
    import llama_cpp.llama as llama_module

    with _OPEN_LOCK:
        current = llama_module.llama_cpp.llama_model_default_params
        if getattr(current, "plain_buffers", False):
            return
        original = llama_cpp.llama_model_default_params

        def plain_buffers() -> Any:
            params = original()
            params.use_extra_bufts = False
            return params

        plain_buffers.plain_buffers = True  # type: ignore[attr-defined]
        llama_module.llama_cpp.llama_model_default_params = plain_buffers


def open_llama(path: Path, *, n_ctx: int = 2048, lora_path: Path | None = None, n_threads: int | None = None
               ) -> Any:
    """Load a GGUF model; `lora_path` applies an adapter."""
    import llama_cpp

    if n_threads is None:
        # All cores of the small robot computer; NRTRANS_THREADS overrides it
        # where other work shares them (spinning llama.cpp threads that lose
        # their core make decoding slower, not faster).
        n_threads = int(os.environ.get("NRTRANS_THREADS", "0")) or min(4, os.cpu_count() or 1)
    use_plain_cpu_buffers()
    return llama_cpp.Llama(model_path=str(path), n_ctx=n_ctx, n_batch=512, verbose=False,
                           lora_path=None if lora_path is None else str(lora_path), n_threads=n_threads)


class _AbortFlag:
    """llama.cpp's abort callback, answered without Python: a C string that is empty or not.

    The callback runs between the nodes of every compute graph. A Python callback
    would take the GIL hundreds of times per token; libc's `strlen` on this buffer
    answers "abort?" (0 or 1, read as a C bool) with no Python at all.
    """

    def __init__(self, llm: Any) -> None:
        import llama_cpp

        self._buffer = ctypes.create_string_buffer(2)
        strlen = ctypes.cast(ctypes.CDLL(None).strlen, ctypes.c_void_p).value
        assert strlen is not None, "libc has strlen"
        # Kept referenced: llama.cpp holds only the raw pointers.
        self._callback = llama_cpp.ggml_abort_callback(strlen)
        llama_cpp.llama_set_abort_callback(llm._ctx.ctx, self._callback, ctypes.cast(self._buffer, ctypes.c_void_p))

    def set(self) -> None:
        self._buffer[0] = b"x"

    def clear(self) -> None:
        self._buffer[0] = b"\0"

    def is_set(self) -> bool:
        return self._buffer[0] != b"\0"


class _Trie:
    __slots__ = ("children", "tokens")

    def __init__(self) -> None:
        self.children: dict[str, _Trie] = {}
        self.tokens: list[int] = []


class Vocabulary:
    """The model's token pieces that can occur in RSL, as a trie."""

    def __init__(self, llm: Any) -> None:
        import llama_cpp

        vocab = llm._model.vocab
        n_vocab = llm.n_vocab()
        buffer = ctypes.create_string_buffer(64)
        self.pieces: list[bytes] = []
        self.root = _Trie()
        for token in range(n_vocab):
            n = llama_cpp.llama_token_to_piece(vocab, token, buffer, 64, 0, False)
            piece = buffer.raw[:n] if n > 0 else b""
            self.pieces.append(piece)
            if not piece or llama_cpp.llama_vocab_is_control(vocab, token):
                continue
            try:
                text = piece.decode("ascii")
            except UnicodeDecodeError:
                continue
            if all(c in ALPHABET for c in text):
                node = self.root
                for char in text:
                    node = node.children.setdefault(char, _Trie())
                node.tokens.append(token)
        self.eos = llm.token_eos()


class TokenMasks:
    """For each automaton state: the allowed tokens and the state after each."""

    def __init__(self, automaton: RslAutomaton, vocabulary: Vocabulary) -> None:
        self.automaton = automaton
        self.vocabulary = vocabulary
        self._cache: dict[State, tuple[np.ndarray, list[State]]] = {}
        self._closing: dict[State, tuple[np.ndarray, list[State]]] = {}
        self._ends: dict[State, np.ndarray] = {}

    def closing(self, state: State) -> tuple[np.ndarray, list[State]]:
        """The tokens from `state` that end the program without starting another statement."""
        found = self._closing.get(state)
        if found is None:
            ids, states = self.at(state)
            keep = [i for i, s in enumerate(states) if s in (END, ("S", True))
                    and b";" not in self.vocabulary.pieces[int(ids[i])]]
            found = (ids[keep], [states[i] for i in keep])
            self._closing[state] = found
        return found

    def ends(self, state: State) -> np.ndarray:
        """Positions in `at(state)` of the tokens that end the program."""
        found = self._ends.get(state)
        if found is None:
            found = self._ends[state] = np.asarray([i for i, s in enumerate(self.at(state)[1]) if s == END],
                                                   dtype=np.int64)
        return found

    def at(self, state: State) -> tuple[np.ndarray, list[State]]:
        found = self._cache.get(state)
        if found is None:
            ids: list[int] = []
            states: list[State] = []
            self._collect(state, self.vocabulary.root, ids, states)
            found = (np.asarray(ids, dtype=np.int64), states)
            self._cache[state] = found
        return found

    def _collect(self, state: State, node: _Trie, ids: list[int], states: list[State]) -> None:
        step = self.automaton.step
        for char, child in node.children.items():
            after = step(state, char)
            if after is None:
                continue
            if child.tokens:
                ids.extend(child.tokens)
                states.extend([after] * len(child.tokens))
            if after != END:
                self._collect(after, child, ids, states)


class LocalEngine:
    """A loaded model; `generate` continues a prompt greedily, reusing the KV cache of a shared prefix."""

    def __init__(self, path: Path, *, lora_path: Path | None = None, n_ctx: int = 4096) -> None:
        self.path = path
        self.llm = open_llama(path, n_ctx=n_ctx, lora_path=lora_path)
        self.vocabulary = Vocabulary(self.llm)
        self.chat_template: str = self.llm.metadata.get("tokenizer.chat_template", "")
        self._masks: dict[Any, TokenMasks] = {}
        self._abort = _AbortFlag(self.llm)

    def masks(self, automaton: RslAutomaton) -> TokenMasks:
        masks = self._masks.get(automaton.key)
        if masks is None:
            if len(self._masks) > 64:
                self._masks.clear()
            masks = self._masks[automaton.key] = TokenMasks(automaton, self.vocabulary)
        return masks

    def generate(self, prompt: str, automaton: RslAutomaton | None, max_tokens: int,
                 cancel: CancelFlag | None = None, fork: Fork | None = None) -> Generation:
        """Raises `GenerationCancelled` within milliseconds of `cancel` being set, even mid-token.

        With `fork` (which needs the grammar) the output starts with the fork's tokens and its other
        token, and goes on greedily from there; the KV cache of the earlier generation is reused."""
        if fork is not None and automaton is None:
            raise ValueError("a fork follows the grammar's states; it needs an automaton")
        if cancel is None:
            return self._generate(prompt, automaton, max_tokens, fork)
        if cancel.is_set():
            raise GenerationCancelled("generation cancelled")
        done = threading.Event()

        def watch() -> None:
            # One llama_decode call can take a second on a loaded CPU; the abort flag ends it early.
            while not done.wait(_CANCEL_POLL_S):
                if cancel.is_set():
                    self._abort.set()
                    return

        watcher = threading.Thread(target=watch, name="nrtrans-cancel-watch", daemon=True)
        watcher.start()
        try:
            return self._generate(prompt, automaton, max_tokens, fork)
        except RuntimeError:
            if self._abort.is_set():
                raise GenerationCancelled("generation cancelled") from None
            raise
        finally:
            done.set()
            watcher.join()
            self._abort.clear()

    def _generate(self, prompt: str, automaton: RslAutomaton | None, max_tokens: int,
                  fork: Fork | None = None) -> Generation:
        import llama_cpp

        def check() -> None:
            if self._abort.is_set():
                raise GenerationCancelled("generation cancelled")

        llm = self.llm
        started = time.perf_counter()
        tokens = llm.tokenize(prompt.encode("utf-8"), add_bos=True, special=False)
        if len(tokens) + max_tokens > llm.n_ctx():
            raise ValueError(f"the prompt is {len(tokens)} tokens; with {max_tokens} to generate it does not "
                             f"fit the context of {llm.n_ctx()}. Shorten the task.")
        # A fork's tokens before its other choice were evaluated by the earlier generation: only the
        # cache is checked for them, and they are replayed through the grammar without new logits.
        replayed = list(fork.tokens) if fork is not None else []
        forced = [*replayed, fork.token] if fork is not None else []
        feed = tokens + replayed
        reused = 0
        cached = llm.input_ids[:llm.n_tokens]
        limit = min(len(cached), len(feed) - 1)
        while reused < limit and cached[reused] == feed[reused]:
            reused += 1
        llm.n_tokens = reused
        llm.eval(feed[reused:])
        prompt_done = time.perf_counter()

        n_vocab = llm.n_vocab()
        masks = None if automaton is None else self.masks(automaton)
        state: State = ("S", False)
        out = bytearray()
        generated = 0
        finished = False
        pieces = self.vocabulary.pieces
        first_piece, first_probability = "", 0.0
        chosen: list[float] = list(fork.probabilities) if fork is not None else []
        endings: list[tuple[int, int, float]] = []
        picked: list[int] = []
        forks: list[tuple[int, int, float]] = []
        while generated < max_tokens:
            check()
            replay = generated < len(replayed)
            if not replay:
                logits = np.ctypeslib.as_array(llama_cpp.llama_get_logits_ith(llm._ctx.ctx, -1),
                                               shape=(n_vocab,))
            if generated == 0 and not replay:
                top = int(np.argmax(logits))
                first_probability = float(1.0 / np.exp(logits - logits[top]).sum())
                first_piece = pieces[top].decode("utf-8", errors="replace")
            if masks is None:
                token = int(np.argmax(logits))
                if token == self.vocabulary.eos:
                    finished = True
                    break
            else:
                statements = out.count(b";")
                full = statements >= automaton.max_statements  # type: ignore[union-attr]
                ids, states = masks.closing(state) if full else masks.at(state)
                if len(ids) == 0:
                    break
                if generated < len(forced):
                    hits = np.flatnonzero(ids == forced[generated])
                    if not len(hits):
                        raise ValueError(f"the fork's token {forced[generated]} is not allowed by the grammar "
                                         f"after {out.decode('utf-8', errors='replace')!r}")
                    choice = int(hits[0])
                if not replay:
                    allowed = logits[ids]
                    if generated >= len(forced):
                        choice = int(np.argmax(allowed))
                    weights = np.exp(allowed - allowed.max())
                    total = float(weights.sum())
                    chosen.append(float(weights[choice] / total))
                    ending = masks.ends(state)
                    if len(ending) and states[choice] != END:
                        endings.append((statements, len(chosen) - 1, float(weights[ending].sum() / total)))
                    if len(ids) > 1 and generated >= len(forced):
                        others = weights.copy()
                        others[choice] = 0.0
                        second = int(np.argmax(others))
                        if others[second] / total >= FORK_RECORD_FLOOR and states[second] != END:
                            forks.append((len(chosen) - 1, int(ids[second]), float(others[second] / total)))
                token, state = int(ids[choice]), states[choice]
            out += pieces[token]
            picked.append(token)
            generated += 1
            if state == END or (masks is None and b"\n\n" in out):
                finished = True
                break
            if not replay:
                llm.eval([token])
        text = out.decode("utf-8", errors="replace")
        if masks is None and "\n\n" in text:
            text = text[: text.index("\n\n") + 2]
        done = time.perf_counter()
        return Generation(text=text, prompt_tokens=len(tokens), reused_tokens=reused, generated_tokens=generated,
                          prompt_ms=(prompt_done - started) * 1000, generate_ms=(done - prompt_done) * 1000,
                          finished=finished, first_piece=first_piece, first_probability=first_probability,
                          token_probabilities=tuple(chosen), endings=tuple(endings), tokens=tuple(picked),
                          forks=tuple(forks))

    def close(self) -> None:
        close = getattr(self.llm, "close", None)
        if close is not None:
            close()
