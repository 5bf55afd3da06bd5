"""The OpenAI-compatible HTTP backend against a real llama_cpp.server on loopback."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

from agent.translate import Translator
from agent.translate.http import EndpointError
from rsl.profile import Profile

SERVE = (
    "import sys\n"
    "from agent.translate.engine import use_plain_cpu_buffers\n"
    "use_plain_cpu_buffers()\n"
    "from llama_cpp.server.__main__ import main\n"
    "sys.argv = ['llama_cpp.server'] + sys.argv[1:]\n"
    "main()\n"
)


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@pytest.fixture(scope="module")
def server(model_path: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    pytest.importorskip("llama_cpp.server.app", reason="needs llama-cpp-python[server] (the test extra)")
    port = _free_port()
    # llama.cpp logs a lot while loading: a file, not a pipe nobody drains.
    log = tmp_path_factory.mktemp("llm-server") / "server.log"
    process = subprocess.Popen(
        [sys.executable, "-c", SERVE, "--model", str(model_path), "--host", "127.0.0.1", "--port", str(port),
         "--n_ctx", "4096", "--n_threads", os.environ.get("NRTRANS_THREADS", "2")],
        stdout=subprocess.DEVNULL, stderr=log.open("w"))
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 120
        while True:
            try:
                with urllib.request.urlopen(f"{url}/v1/models", timeout=2) as reply:
                    json.load(reply)
                break
            except OSError:
                if process.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"llama_cpp.server did not start: {log.read_text()[-2000:]}"
                                       ) from None
                time.sleep(0.5)
        yield url
    finally:
        process.terminate()
        process.wait(timeout=30)


def test_endpoint_translates_under_the_grammar(server: str, profile: Profile) -> None:
    translator = Translator.load(profile, endpoint=server)
    result = translator.translate("turn left 90 degrees, then grasp the cup", known_objects=["cup"])
    assert result.model.endswith(f"@{server}")
    for attempt in result.attempts:
        assert all(d.code.is_semantic for d in attempt.diagnostics), attempt
    assert result.verified, result.attempts


def test_unreachable_endpoint_is_a_clear_error(profile: Profile) -> None:
    translator = Translator.load(profile, endpoint=f"http://127.0.0.1:{_free_port()}")
    with pytest.raises(EndpointError, match="cannot reach the LLM endpoint"):
        translator.translate("turn left")
