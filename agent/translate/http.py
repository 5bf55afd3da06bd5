"""A translator backend on an OpenAI-compatible HTTP server (llama.cpp's server on the LAN)."""

from __future__ import annotations

import json
import time
import urllib.error
import urllib.request
from typing import Any

from agent.translate.automaton import RslAutomaton
from agent.translate.engine import CancelFlag, Fork, Generation, GenerationCancelled


class EndpointError(RuntimeError):
    """The HTTP endpoint could not produce a completion; the message says why and what to try."""


class HttpEngine:
    """Sends plain completions with the RSL grammar in llama.cpp's `grammar` field."""

    chat_template = ""

    def __init__(self, endpoint: str, *, model: str | None = None, timeout: float = 60.0) -> None:
        self.endpoint = endpoint.rstrip("/")
        if not self.endpoint.startswith(("http://", "https://")):
            raise EndpointError(f"endpoint {endpoint!r} is not an http(s) URL; "
                                "give it as http://HOST:PORT (the server's /v1 API is used)")
        self.model = model
        self.timeout = timeout
        base = self.endpoint[:-3] if self.endpoint.endswith("/v1") else self.endpoint
        self._url = f"{base}/v1/completions"

    def generate(self, prompt: str, automaton: RslAutomaton | None, max_tokens: int,
                 cancel: CancelFlag | None = None, fork: Fork | None = None) -> Generation:
        if fork is not None:
            # A server returns no token choices, so its generations offer no forks to take.
            raise ValueError("an OpenAI-compatible endpoint cannot continue from a fork")
        if cancel is not None and cancel.is_set():
            # One request cannot be interrupted; a cancel takes effect before the next.
            raise GenerationCancelled("generation cancelled")
        body: dict[str, Any] = {"prompt": prompt, "max_tokens": max_tokens, "temperature": 0.0,
                                "top_k": 1, "seed": 0}
        if self.model:
            body["model"] = self.model
        if automaton is not None:
            body["grammar"] = automaton.to_gbnf()
        else:
            body["stop"] = ["\n\n"]
        request = urllib.request.Request(self._url, data=json.dumps(body).encode("utf-8"),
                                         headers={"Content-Type": "application/json"}, method="POST")
        started = time.perf_counter()
        try:
            with urllib.request.urlopen(request, timeout=self.timeout) as response:
                reply = json.loads(response.read().decode("utf-8"))
        except urllib.error.HTTPError as exc:
            detail = exc.read().decode("utf-8", errors="replace")[:300]
            raise EndpointError(f"{self._url} answered HTTP {exc.code}: {detail}") from None
        except (urllib.error.URLError, TimeoutError, OSError) as exc:
            reason = getattr(exc, "reason", exc)
            raise EndpointError(f"cannot reach the LLM endpoint {self._url}: {reason}. "
                                "Check that the server runs and the URL is right, or drop --endpoint "
                                "to use the on-device model.") from None
        except json.JSONDecodeError:
            raise EndpointError(f"{self._url} did not answer with JSON; is it an OpenAI-compatible server?"
                                ) from None
        elapsed = (time.perf_counter() - started) * 1000
        try:
            choice = reply["choices"][0]
            text = str(choice["text"])
        except (KeyError, IndexError, TypeError):
            raise EndpointError(f"{self._url} answered without choices[0].text: {str(reply)[:200]}") from None
        usage = reply.get("usage") or {}
        if automaton is None and "\n\n" not in text:
            text += "\n\n" if choice.get("finish_reason") == "stop" else ""
        return Generation(text=text, prompt_tokens=int(usage.get("prompt_tokens", 0)), reused_tokens=0,
                          generated_tokens=int(usage.get("completion_tokens", 0)), prompt_ms=0.0,
                          generate_ms=elapsed, finished=choice.get("finish_reason") == "stop")

    def close(self) -> None:
        """Nothing is held open between requests."""
