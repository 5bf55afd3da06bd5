"""The main job end to end: start the daemon, send it tasks over its socket, show what happens.

Starts a real `nrtrans serve` (simulator, embedded model) in a child process
with its own socket, waits for READY=1 on a notify socket as systemd would,
follows each task's events to the end, then stops the daemon with SIGTERM.
The daemon records each task's run (`[robot] record`); the demo prints where
the pictures are.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from agent.client import Client, ClientError, describe_event
from agent.daemon.config import Config

DEFAULT_TASKS = ("move forward one meter then turn left",)


def run_demo(
    tasks: Sequence[str] = DEFAULT_TASKS,
    *,
    realtime_factor: float = 1.0,
    state_dir: Path | None = None,
    start_timeout: float = 600.0,
) -> int:
    """Exit status 0 when every task was done."""
    state = state_dir or Config().state_path() / "demo"
    pictures = state / "pictures"
    with tempfile.TemporaryDirectory(prefix="nrtrans-demo-") as scratch:
        folder = Path(scratch)
        config = folder / "config.toml"
        config.write_text(
            f'state_dir = "{state}"\nlog_level = "warning"\n[api]\nsocket = "{folder / "api.sock"}"\n'
            f'[robot]\nrealtime_factor = {realtime_factor}\nrecord = "{pictures}"\n[speech]\nenabled = false\n',
            encoding="utf-8",
        )
        notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        notify.bind(str(folder / "notify"))
        notify.settimeout(0.5)
        env = {**os.environ, "NOTIFY_SOCKET": str(folder / "notify")}
        env.pop("NRTRANS_SOCKET", None)  # the daemon listens where the demo's config says
        print("starting the daemon: nrtrans serve (simulator, embedded model)", flush=True)
        daemon = subprocess.Popen([sys.executable, "-m", "agent.cli", "serve", "--config", str(config)], env=env)
        try:
            if not _wait_ready(notify, daemon, start_timeout):
                print("nrtrans demo: error: the daemon did not start; its errors are above", file=sys.stderr)
                return 1
            results = [_run_task(folder / "api.sock", task, pictures) for task in tasks]
        except ClientError as exc:
            print(f"nrtrans demo: error: {exc}", file=sys.stderr)
            return 1
        finally:
            notify.close()
            if daemon.poll() is None:
                print("stopping the daemon (SIGTERM)", flush=True)
                daemon.send_signal(signal.SIGTERM)
                daemon.wait(60)
        print(f"audit log: {state / 'audit.jsonl'}")
        return 0 if all(results) else 1


def _wait_ready(notify: socket.socket, daemon: subprocess.Popen[bytes], timeout: float) -> bool:
    started = time.monotonic()
    while time.monotonic() - started < timeout:
        if daemon.poll() is not None:
            return False
        try:
            message = notify.recv(65536).decode("utf-8", "replace").split("\n")
        except TimeoutError:
            continue
        for line in message:
            if line.startswith("STATUS="):
                print(f"  {line[len('STATUS=') :]}", flush=True)
        if "READY=1" in message:
            print(f"daemon ready after {time.monotonic() - started:.1f} s", flush=True)
            return True
    return False


def _run_task(path: Path, task: str, pictures: Path) -> bool:
    print(f'\n$ nrtrans send "{task}"', flush=True)
    with Client.connect(path, timeout=None) as client:
        task_id = client.submit(text=task, follow=True)
        last = None
        for event in client.follow(task_id):
            print(describe_event(event), flush=True)
            last = event
    _show_pictures(pictures / task_id)
    return last is not None and last["event"] == "done"


def _show_pictures(folder: Path) -> None:
    """Where the daemon saved the pictures of a task's run (none when nothing ran)."""
    plot, animation = folder / "trajectory.png", folder / "run.gif"
    if not plot.exists():
        return
    print(f"trajectory plot: {plot}", flush=True)
    if animation.exists():
        print(f"animation:       {animation}", flush=True)
    snapshots = sorted(folder.glob("step_*.png"))
    if snapshots:
        print(f"camera snapshots: {len(snapshots)} in {folder}", flush=True)
