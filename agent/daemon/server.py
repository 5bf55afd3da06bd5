"""The local socket API: a Unix stream socket carrying newline-delimited JSON.

Each connection has its own bounded outbound queue and writer task, so a
client that stops reading is cut off when its queue fills instead of
slowing the robot or the other clients. Requests on one connection are
answered in order; a malformed frame gets an error reply and the
connection carries on.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import socket
import stat
import struct
from pathlib import Path
from typing import Any

from agent.daemon.config import Config
from agent.daemon.events import Event
from agent.daemon.protocol import ProtocolError, Request, decode_request, encode, error_frame, reply_frame
from agent.daemon.service import Service, StartupError
from agent.daemon.tasks import Peer

log = logging.getLogger(__name__)

_READ_CHUNK = 65536
# Past `api.max_clients`, this many more connections may each send one `estop`, within this time.
_RESERVED_CONNECTIONS = 16
_RESERVED_WAIT_S = 5.0


def peer_credentials(sock: socket.socket) -> Peer:
    raw = sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i"))
    pid, uid, gid = struct.unpack("3i", raw)
    return Peer(pid, uid, gid)


class Client:
    def __init__(
        self, server: SocketServer, reader: asyncio.StreamReader, writer: asyncio.StreamWriter, peer: Peer
    ) -> None:
        self.server = server
        self.reader = reader
        self.writer = writer
        self.peer = peer
        self.loop = asyncio.get_running_loop()
        self.out: asyncio.Queue[bytes | None] = asyncio.Queue(server.config.api.client_queue)
        self.subscriptions: list[int] = []
        self.closing = False

    def send(self, frame: dict[str, Any]) -> None:
        """Queue a frame; only ever called on the event loop."""
        if self.closing:
            return
        try:
            self.out.put_nowait(encode(frame))
        except asyncio.QueueFull:
            log.warning("client pid %d fell %d frames behind; disconnecting it", self.peer.pid, self.out.maxsize)
            self.close(abort=True)

    def deliver(self, event: Event) -> None:
        """Event bus callback; may run on any thread."""
        if not self.closing:
            self.loop.call_soon_threadsafe(self.send, event.frame())

    def close(self, *, abort: bool = False) -> None:
        if self.closing:
            return
        self.closing = True
        for key in self.subscriptions:
            self.server.service.events.unsubscribe(key)
        self.subscriptions.clear()
        try:
            self.out.put_nowait(None)
        except asyncio.QueueFull:
            abort = True
        if abort:
            # Cut off without waiting for a reader that may never read again.
            self.writer.transport.abort()

    async def write_loop(self) -> None:
        try:
            while True:
                data = await self.out.get()
                if data is None:
                    break
                self.writer.write(data)
                await self.writer.drain()
        except (ConnectionError, OSError):
            pass
        finally:
            self.closing = True
            self.writer.close()

    async def read_loop(self) -> None:
        limit = self.server.config.api.max_line_bytes
        buffer = bytearray()
        discarding = False
        while not self.closing:
            try:
                chunk = await self.reader.read(_READ_CHUNK)
            except (ConnectionError, OSError):
                break
            if not chunk:
                break
            buffer += chunk
            while True:
                newline = buffer.find(b"\n")
                if newline < 0:
                    if len(buffer) >= limit and not discarding:
                        discarding = True
                        self.send(
                            error_frame(
                                "too_long",
                                f"the frame is longer than {limit} bytes",
                                "send smaller frames; see api.max_line_bytes in docs/config.md",
                            )
                        )
                    if discarding:
                        buffer.clear()
                    break
                line = bytes(buffer[:newline])
                del buffer[: newline + 1]
                if discarding:
                    # The tail of an oversized frame, already answered.
                    discarding = False
                    continue
                if len(line) + 1 > limit:
                    self.send(
                        error_frame(
                            "too_long",
                            f"the frame is longer than {limit} bytes",
                            "send smaller frames; see api.max_line_bytes in docs/config.md",
                        )
                    )
                    continue
                if line.strip():
                    await self.handle(line)
                if self.closing:
                    return

    async def handle(self, line: bytes) -> None:
        decoded = decode_request(line, max_task_chars=self.server.config.api.max_task_chars)
        if isinstance(decoded, ProtocolError):
            self.send(decoded.frame())
            return
        try:
            self.send(await self.server.dispatch(self, decoded))
        except ProtocolError as exc:
            self.send(error_frame(exc.code, exc.message, exc.help, op=decoded.op, request_id=decoded.id))
        except Exception as exc:
            log.exception("request %s failed", decoded.op)
            self.send(
                error_frame(
                    "internal",
                    f"{decoded.op} failed inside the daemon: {exc}",
                    "this is a bug; the journal has the details",
                    op=decoded.op,
                    request_id=decoded.id,
                )
            )


class SocketServer:
    def __init__(self, config: Config, service: Service) -> None:
        self.config = config
        self.service = service
        self.clients: set[Client] = set()
        self._server: asyncio.AbstractServer | None = None
        self._path: Path | None = None
        self._reserved = 0

    async def start(self, inherited_fd: int | None = None) -> None:
        if inherited_fd is not None:
            sock = socket.socket(fileno=inherited_fd)
        else:
            self._path = self.config.socket_path()
            sock = _bind(self._path, int(self.config.api.socket_mode, 8))
        sock.setblocking(False)
        self._server = await asyncio.start_unix_server(self._accept, sock=sock, limit=_READ_CHUNK)

    async def close(self) -> None:
        if self._server is not None:
            self._server.close()
        for client in list(self.clients):
            client.close()
        if self._path is not None:
            with contextlib.suppress(FileNotFoundError):
                self._path.unlink()

    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        sock = writer.get_extra_info("socket")
        peer = peer_credentials(sock)
        refusal = self._refusal(peer)
        if refusal is not None:
            await _refuse(reader, writer, refusal)
            return
        if len(self.clients) >= self.config.api.max_clients:
            await self._estop_only(reader, writer, peer)
            return
        client = Client(self, reader, writer, peer)
        writer_task = asyncio.create_task(client.write_loop())
        self.clients.add(client)
        try:
            await client.read_loop()
        finally:
            self.clients.discard(client)
            client.close()
            with contextlib.suppress(Exception):
                await asyncio.wait_for(writer_task, 5.0)

    def _refusal(self, peer: Peer) -> dict[str, Any] | None:
        api = self.config.api
        restricted = bool(api.allowed_uids or api.allowed_gids)
        allowed = peer.uid == os.getuid() or peer.uid in api.allowed_uids or peer.gid in api.allowed_gids
        if restricted and not allowed:
            log.warning(
                "refused a connection from uid %d gid %d (pid %d): not on the allow-list", peer.uid, peer.gid, peer.pid
            )
            return error_frame(
                "forbidden",
                f"uid {peer.uid} / gid {peer.gid} may not use this daemon",
                "ask the operator to add your uid to api.allowed_uids or your group to api.allowed_gids",
            )
        return None

    async def _estop_only(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter, peer: Peer) -> None:
        """Serve one `estop` on a connection past the client limit; anything else gets `busy`.

        An emergency stop must get through however many clients hold a connection.
        """
        api = self.config.api
        busy = error_frame(
            "busy",
            f"{len(self.clients)} clients are connected (the limit is {api.max_clients}); "
            "only an `estop` is served on this connection",
            "close idle connections and try again",
        )
        if self._reserved >= _RESERVED_CONNECTIONS:
            await _refuse(reader, writer, busy)
            return
        self._reserved += 1
        try:
            try:
                async with asyncio.timeout(_RESERVED_WAIT_S):
                    line = await reader.readline()
            except (TimeoutError, ValueError, ConnectionError, OSError):
                line = b""
            decoded = decode_request(line, max_task_chars=api.max_task_chars) if line.strip() else None
            if isinstance(decoded, Request) and decoded.op == "estop":
                self._estop(peer, decoded.body)
                reply = reply_frame(decoded, latched=True)
            elif isinstance(decoded, ProtocolError) and decoded.op == "estop":
                reply = decoded.frame()
            else:
                reply = {**busy, **({"op": decoded.op, "id": decoded.id} if decoded is not None else {})}
            await _refuse(reader, writer, reply)
        finally:
            self._reserved -= 1

    def _estop(self, peer: Peer, body: dict[str, Any]) -> None:
        self.service.estop(body.get("reason") or f"requested by uid {peer.uid} (pid {peer.pid})")

    async def dispatch(self, client: Client, request: Request) -> dict[str, Any]:
        service = self.service
        body = request.body
        if request.op == "submit":

            def follow(task: Any) -> None:
                client.subscriptions.append(service.events.subscribe(client.deliver, task.id))

            task, position = service.submit(
                source="socket",
                text=body.get("text"),
                rsl=body.get("rsl"),
                peer=client.peer,
                before_queue=follow if body.get("follow") else None,
            )
            return reply_frame(request, task=task.id, state=task.state.value, position=position)
        if request.op == "status":
            if "task" in body:
                return reply_frame(request, task=service.task(body["task"]).record())
            return reply_frame(request, daemon=service.daemon_status())
        if request.op == "cancel":
            task = service.cancel(body["task"])
            return reply_frame(request, task=task.id, state=task.state.value)
        if request.op == "confirm":
            task = service.confirm(body["task"], bool(body["accept"]), f"uid {client.peer.uid}")
            return reply_frame(request, task=task.id, accepted=bool(body["accept"]))
        if request.op == "estop":
            self._estop(client.peer, body)
            return reply_frame(request, latched=True)
        if request.op == "reset":
            service.reset()
            return reply_frame(request, latched=False)
        if request.op == "subscribe":
            client.subscriptions.append(service.events.subscribe(client.deliver, body.get("task")))
            return reply_frame(request, subscribed=True)
        if request.op == "listen":
            service.listen()
            return reply_frame(request, listening=True)
        if request.op == "health":
            healthy, components = await asyncio.to_thread(service.health)
            components["api"] = {
                "ok": True,
                "clients": len(self.clients),
                "socket": str(self._path) if self._path else "inherited (socket activation)",
            }
            return reply_frame(request, healthy=healthy, components=components)
        if request.op == "history":
            records = await asyncio.to_thread(service.audit.recent, int(body.get("limit", 20)))
            return reply_frame(request, tasks=records)
        raise AssertionError(f"no handler for {request.op}")


async def _refuse(reader: asyncio.StreamReader, writer: asyncio.StreamWriter, refusal: dict[str, Any]) -> None:
    """Send one error and close gracefully.

    What the client already sent is read and dropped first: closing a Unix socket with
    unread data resets the connection, and the client would never see the reason.
    """
    try:
        writer.write(encode(refusal))
        await writer.drain()
        writer.write_eof()
        async with asyncio.timeout(2.0):
            while await reader.read(_READ_CHUNK):
                pass
    except (TimeoutError, ConnectionError, OSError):
        pass
    finally:
        writer.close()


def _bind(path: Path, mode: int) -> socket.socket:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise StartupError(
            f"cannot create the socket directory {path.parent}: {exc.strerror}\n"
            "  = help: choose a writable place with --socket"
        ) from exc
    if path.exists() or path.is_symlink():
        if not stat.S_ISSOCK(path.lstat().st_mode):
            raise StartupError(
                f"{path} exists and is not a socket\n  = help: remove it or choose another path with --socket"
            )
        probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            probe.connect(str(path))
        except OSError:
            path.unlink()  # left over from a daemon that died
        else:
            raise StartupError(
                f"another nrtrans daemon is already serving {path}\n"
                "  = help: stop it first, or choose another path with --socket"
            )
        finally:
            probe.close()
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    # Bound under a strict umask so the socket is never briefly open to everyone.
    old_umask = os.umask(0o177)
    try:
        sock.bind(str(path))
    except OSError as exc:
        sock.close()
        raise StartupError(
            f"cannot create the socket {path}: {exc.strerror}\n  = help: choose a writable place with --socket"
        ) from exc
    finally:
        os.umask(old_umask)
    os.chmod(path, mode)
    sock.listen(128)
    return sock
