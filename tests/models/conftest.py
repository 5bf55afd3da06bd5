"""A real HTTP server on loopback that serves model files, with Range support and faults on demand."""

from __future__ import annotations

import http.server
import re
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest


@dataclass
class Served:
    """What the server holds and how it misbehaves; tests change it between requests."""

    files: dict[str, bytes] = field(default_factory=dict)
    # Send only this many body bytes of the next response, then drop the
    # connection (while announcing the full length), like a network cut.
    cut_after: int | None = None
    # Answer every request with the whole file, as servers without Range support do.
    ignore_range: bool = False
    ranges_seen: list[str | None] = field(default_factory=list)


class _Handler(http.server.BaseHTTPRequestHandler):
    served: Served

    def do_GET(self) -> None:
        body = self.served.files.get(self.path)
        header = self.headers.get("Range")
        self.served.ranges_seen.append(header)
        if body is None:
            self.send_error(404)
            return
        start = 0
        if header and not self.served.ignore_range:
            match = re.fullmatch(r"bytes=(\d+)-", header)
            if match is None:
                self.send_error(400)
                return
            start = int(match.group(1))
            if start >= len(body):
                self.send_response(416)
                self.send_header("Content-Range", f"bytes */{len(body)}")
                self.send_header("Content-Length", "0")
                self.end_headers()
                return
            self.send_response(206)
            self.send_header("Content-Range", f"bytes {start}-{len(body) - 1}/{len(body)}")
        else:
            self.send_response(200)
        rest = body[start:]
        self.send_header("Content-Length", str(len(rest)))
        self.send_header("Accept-Ranges", "bytes")
        self.end_headers()
        cut = self.served.cut_after
        if cut is not None:
            self.served.cut_after = None
            self.wfile.write(rest[:cut])
            self.wfile.flush()
            self.close_connection = True
            return
        self.wfile.write(rest)

    def log_message(self, format: str, *args: object) -> None:
        pass


@pytest.fixture
def http_server() -> Iterator[tuple[str, Served]]:
    served = Served()
    handler = type("Handler", (_Handler,), {"served": served})
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}", served
    finally:
        server.shutdown()
        server.server_close()
        thread.join(5)


@pytest.fixture
def model_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    home = tmp_path / "models"
    monkeypatch.setenv("NRTRANS_MODEL_DIR", str(home))
    return home
