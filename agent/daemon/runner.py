"""`nrtrans serve`: load, tell systemd we are ready, serve until SIGTERM.

READY=1 goes out only after the audit log, profile, model, backend and
socket are all up; a failure before that exits non-zero with the reason,
so systemd never considers a half-loaded daemon started.
"""

from __future__ import annotations

import asyncio
import logging
import os
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path

from agent.daemon.config import Config, ConfigError, load_config
from agent.daemon.notify import Notifier, listen_fds, watchdog_interval
from agent.daemon.preflight import startup_problems
from agent.daemon.server import SocketServer
from agent.daemon.service import Service, StartupError

log = logging.getLogger("nrtrans.daemon")


def serve(config: Config, *, config_file: Path | None = None, reload: Callable[[], Config] | None = None) -> int:
    notifier = Notifier()
    started = time.monotonic()

    def status(text: str) -> None:
        # The idle line is logged once, when the daemon is ready, not again after every task.
        if text != service.idle_status():
            log.info("%s", text)
        notifier.status(text)

    fds = listen_fds()
    problems = startup_problems(config, socket_activated=bool(fds))
    if problems:
        for problem in problems:
            print(f"nrtrans serve: error: {problem}", file=sys.stderr)
        notifier.send(f"STATUS=failed to start: {problems[0]}")
        notifier.close()
        return 1
    service = Service(config, on_status=status)
    try:
        service.load()
    except StartupError as exc:
        print(f"nrtrans serve: error: {exc}", file=sys.stderr)
        notifier.send(f"STATUS=failed to start: {str(exc).splitlines()[0]}")
        service.shutdown("startup failed")
        return 1
    try:
        code = asyncio.run(_serve(service, notifier, started, fds, config_file, reload))
    except StartupError as exc:
        print(f"nrtrans serve: error: {exc}", file=sys.stderr)
        service.shutdown("startup failed")
        code = 1
    finally:
        notifier.close()
    if service.worker_busy():
        # Still inside the model after the grace period, with every record already final:
        # leave now rather than finalize the interpreter under a running native thread.
        log.warning("the translator did not finish within the grace period; exiting without waiting for it")
        log.info("stopped (exit status %d)", code)
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    log.info("stopped (exit status %d)", code)
    return code


async def _serve(
    service: Service,
    notifier: Notifier,
    started: float,
    fds: list[int],
    config_file: Path | None,
    reload: Callable[[], Config] | None,
) -> int:
    loop = asyncio.get_running_loop()
    server = SocketServer(service.config, service)
    await server.start(fds[0] if fds else None)
    stop = asyncio.Event()
    stop_reason: list[str] = []

    def on_term(name: str) -> None:
        stop_reason.append(name)
        stop.set()

    def on_hup() -> None:
        if reload is None:
            return
        notifier.reloading()
        try:
            new = reload()
        except ConfigError as exc:
            log.error("SIGHUP: keeping the current configuration: %s", exc)
        else:
            later = service.apply_config(new)
            server.config = service.config
            if later:
                log.warning("SIGHUP: configuration reloaded; these change only on restart: %s", ", ".join(later))
            else:
                log.info("SIGHUP: configuration reloaded from %s", config_file)
        notifier.send("READY=1", f"STATUS={service.idle_status()}")

    loop.add_signal_handler(signal.SIGTERM, on_term, "SIGTERM")
    loop.add_signal_handler(signal.SIGINT, on_term, "SIGINT")
    loop.add_signal_handler(signal.SIGHUP, on_hup)

    ready_s = time.monotonic() - started
    notifier.ready(service.idle_status())
    log.info("%s (started in %.2f s)", service.idle_status(), ready_s)
    pinger = asyncio.create_task(_watchdog(service, notifier))
    try:
        await stop.wait()
    finally:
        log.info(
            "%s: stopping the robot and finishing the task in progress", stop_reason[0] if stop_reason else "stopping"
        )
        notifier.stopping()
        pinger.cancel()
        await server.close()
        await asyncio.to_thread(service.shutdown, "the daemon is shutting down")
    return 0


async def _watchdog(service: Service, notifier: Notifier) -> None:
    interval = watchdog_interval()
    if interval is None:
        return
    while True:
        # Pinged from the event loop, so a hung loop or a dead worker lets systemd restart us.
        if service.alive():
            notifier.watchdog()
        else:
            log.error("the task worker is not running; withholding the watchdog ping")
        await asyncio.sleep(interval)


def reloader(config_file: Path | None, overrides: dict[str, str | None]) -> Callable[[], Config]:
    def reload() -> Config:
        return load_config(config_file).with_overrides(**overrides)

    return reload
