"""Hostile-client benchmark: fuzzed frames, an estop with every slot held, an estop mid-translation.

Runs the real `nrtrans serve` (embedded model, simulator at real time) and
talks to it over its socket. Writes bench/results/hostile.json.

    .venv/bin/python bench/bench_hostile.py [--frames 10000] [--estops 10] [--translations 5]

- fuzz: frames from a seeded generator (valid requests with random fields,
  lone surrogates, emoji, NULs, truncated and corrupted JSON, random bytes,
  deep nesting), sent by 4 clients at once; each frame must get exactly one
  reply or error. Counted: dropped connections, `internal` errors, and audit
  records left open once the daemon is idle again.
- estop with every slot held: `api.max_clients` connections are held, a
  motion runs, and a new connection sends `estop`; timed from connect to the
  `latched` reply.
- estop mid-translation: a long text task, `estop` 0.2 s after its
  `translating` event; timed from sending `estop` to the task's final event.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from agent.client import Client, ClientError  # noqa: E402
from agent.daemon.audit import read_records  # noqa: E402
from agent.daemon.schemas import REQUESTS  # noqa: E402
from bench.bench_daemon import Daemon, median  # noqa: E402

MAX_CLIENTS = 8
FUZZ_CLIENTS = 4
LONG_TASK = " then ".join(["move forward one meter", "turn left", "look up", "turn right"] * 2)
TARGETS = {
    "fuzz_dropped_connections": 0,
    "fuzz_internal_errors": 0,
    "fuzz_open_audit_records": 0,
    "estop_all_slots_held_max_s": 0.1,
    "estop_mid_translation_final_max_s": 0.5,
}
_PIECES = ["a", "forward 1;", "turnleft 0.05;", "grasp cup;", "\ud800", "\udfff", "\udc00x", "\U0001f600",
           "é", "\x00", "\\", " ", '"', "\u2028", "move forward", "9" * 30]
_FIELDS = ["id", "text", "rsl", "task", "reason", "limit", "follow", "extra", "\ud800"]


def _string(rng: random.Random) -> str:
    return "".join(rng.choice(_PIECES) for _ in range(rng.randint(0, 6)))


def _value(rng: random.Random, depth: int = 0) -> Any:
    kind = rng.randint(0, 7 if depth < 3 else 4)
    if kind <= 1:
        return _string(rng)
    if kind == 2:
        return rng.choice([0, 1, -1, 10**30, 2**63, 1.5, -0.0])
    if kind == 3:
        return rng.choice([None, True, False])
    if kind == 4:
        return rng.choice(["", "status", "x" * 3000])
    if kind == 5:
        return [_value(rng, depth + 1) for _ in range(rng.randint(0, 3))]
    return {_string(rng): _value(rng, depth + 1) for _ in range(rng.randint(0, 3))}


def fuzz_frame(rng: random.Random) -> bytes:
    """One frame with no newline inside; the daemon must answer it with exactly one frame."""
    shape = rng.random()
    ops = [*REQUESTS, "bogus", "\ud800"]
    body: dict[str, Any] = {"v": 1 if rng.random() < 0.9 else _value(rng), "op": rng.choice(ops)}
    for name in rng.sample(_FIELDS, rng.randint(0, 3)):
        body[name] = _string(rng) if name in ("text", "rsl", "reason", "id") and rng.random() < 0.8 else _value(rng)
    # json.dumps escapes a lone surrogate as \\udXXX: valid JSON that decodes to a string no UTF-8 can hold.
    data = json.dumps(body).encode("ascii")
    if shape < 0.15:
        # A submit the daemon may accept: its task must reach a final audit record.
        program = " ".join(rng.choice(["turnleft 0.05;", "lookup 0.1;", "forward 0.02;", "jump;"]) for _ in range(2))
        field = "rsl" if rng.random() < 0.8 else "text"
        task = program if field == "rsl" else rng.choice(["turn left a little", "look up", "go \ud800 left"])
        if rng.random() < 0.3:
            task += rng.choice(_PIECES)
        data = json.dumps({"v": 1, "op": "submit", field: task, "id": _string(rng)}).encode("ascii")
    elif shape < 0.65:
        pass
    elif shape < 0.75:
        data = data[: rng.randint(1, len(data))]
    elif shape < 0.85:
        corrupt = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            corrupt[rng.randrange(len(corrupt))] = rng.randrange(256)
        data = bytes(corrupt)
    elif shape < 0.92:
        data = bytes(rng.randrange(256) for _ in range(rng.randint(1, 200)))
    elif shape < 0.96:
        depth = rng.randint(10, 5000)
        data = b'{"v":1,"op":"status","id":' + b"[" * depth + b"]" * depth + b"}"
    else:
        data = json.dumps(_value(rng)).encode("ascii")
    data = data.replace(b"\n", b" ")
    # A blank line is skipped without an answer; make every frame count.
    return data if data.strip() else b"?"


def bench_fuzz(daemon: Daemon, frames: int, seed: int) -> dict[str, Any]:
    counts = {"frames": 0, "replies": 0, "errors": 0, "internal": 0, "dropped": 0}
    codes: dict[str, int] = {}
    lock = threading.Lock()
    failures: list[str] = []

    def run(index: int, count: int) -> None:
        rng = random.Random(seed * 100 + index)
        client = Client.connect(daemon.socket, timeout=120)
        try:
            for _ in range(count):
                frame = fuzz_frame(rng)
                try:
                    client.send_raw(frame + b"\n")
                    while True:
                        answer = client.read_frame()
                        if answer.get("type") != "event":
                            break
                except (ClientError, OSError, ValueError) as exc:
                    with lock:
                        counts["dropped"] += 1
                        failures.append(f"{frame[:120]!r}: {exc}")
                    client.close()
                    client = Client.connect(daemon.socket, timeout=120)
                    continue
                with lock:
                    counts["frames"] += 1
                    if answer.get("type") == "error":
                        code = answer["error"]["code"]
                        codes[code] = codes.get(code, 0) + 1
                        counts["errors"] += 1
                        if code == "internal":
                            counts["internal"] += 1
                            failures.append(f"{frame[:120]!r}: {answer['error']['message']}")
                    else:
                        counts["replies"] += 1
        finally:
            client.close()

    started = time.monotonic()
    share = frames // FUZZ_CLIENTS
    threads = [
        threading.Thread(target=run, args=(i, share + (frames % FUZZ_CLIENTS if i == 0 else 0)))
        for i in range(FUZZ_CLIENTS)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    took = time.monotonic() - started
    with Client.connect(daemon.socket, timeout=120) as client:
        client.estop("end of the fuzz")
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline:
            status = client.status()
            if status["current"] is None and status["queued"] == 0:
                break
            time.sleep(0.2)
        client.reset()
        healthy = client.health()["healthy"]
    last: dict[str, dict[str, Any]] = {}
    for path in sorted((daemon.workdir / "state").glob("audit.jsonl*"), reverse=True):
        for record in read_records(path):
            last[record["task"]] = record
    open_records = [task for task, record in last.items() if not record.get("final")]
    print(f"  {counts['frames']} frames answered in {took:.1f} s; dropped {counts['dropped']}, "
          f"internal {counts['internal']}, audit records left open {len(open_records)}", flush=True)
    return {
        **counts,
        "seconds": round(took, 1),
        "error_codes": dict(sorted(codes.items())),
        "tasks_in_audit": len(last),
        "open_audit_records": len(open_records),
        "healthy_after": healthy,
        "failures": failures[:20],
    }


def bench_estop_slots_held(daemon: Daemon, count: int) -> list[float]:
    holders = [Client.connect(daemon.socket, timeout=60) for _ in range(MAX_CLIENTS)]
    times = []
    try:
        for holder in holders:
            holder.subscribe()
        mover = holders[0]
        for _ in range(count):
            # Long, so that it still runs at the estop even where the simulator catches up after idle.
            task = mover.submit(rsl="turnleft 3.0;\nturnright 3.0;\n" * 5, follow=True)
            for event in mover.events():
                if event["event"] == "executing" and event["task"] == task:
                    break
            time.sleep(0.2)
            sent = time.perf_counter()
            with Client.connect(daemon.socket, timeout=10) as operator:
                reply = operator.estop("benchmark, every slot held")
            times.append(time.perf_counter() - sent)
            assert reply["latched"] is True
            final = list(mover.follow(task))[-1]
            assert final["event"] == "cancelled", final
            mover.reset()
    finally:
        for holder in holders:
            holder.close()
    return times


def bench_estop_mid_translation(daemon: Daemon, count: int) -> tuple[list[float], list[bool]]:
    times, still = [], []
    with Client.connect(daemon.socket, timeout=300) as client, Client.connect(daemon.socket, timeout=60) as operator:
        for _ in range(count):
            before = client.health()["components"]["robot"]["state"]["pose"]
            task = client.submit(text=LONG_TASK, follow=True)
            names = []
            for event in client.events():
                names.append(event["event"])
                if event["event"] == "translating" and event["task"] == task:
                    break
            time.sleep(0.2)
            sent = time.perf_counter()
            operator.estop("benchmark, mid-translation")
            rest = list(client.follow(task))
            times.append(time.perf_counter() - sent)
            names += [e["event"] for e in rest]
            after = client.health()["components"]["robot"]["state"]["pose"]
            still.append(after == before and "executing" not in names)
            assert rest[-1]["event"] == "cancelled", names
            operator.reset()
    return times, still


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=10_000, help="fuzzed frames in all (default 10000)")
    parser.add_argument("--estops", type=int, default=10, help="estops with every slot held (default 10)")
    parser.add_argument("--translations", type=int, default=5, help="estops mid-translation (default 5)")
    parser.add_argument("--seed", type=int, default=13)
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" / "hostile.json")
    args = parser.parse_args()

    workdir = Path(tempfile.mkdtemp(prefix="nrhostile-", dir="/tmp"))
    daemon = Daemon(workdir, 1.0)
    text = daemon.config.read_text().replace("[api]\n", f"[api]\nmax_clients = {MAX_CLIENTS}\n", 1)
    daemon.config.write_text(text + "[tasks]\nqueue_size = 2\n")
    try:
        daemon.start()
        print(f"fuzz: {args.frames} frames from {FUZZ_CLIENTS} clients ...", flush=True)
        fuzz = bench_fuzz(daemon, args.frames, args.seed)
        print(f"estop with all {MAX_CLIENTS} client slots held, a motion running ...", flush=True)
        held = bench_estop_slots_held(daemon, args.estops)
        print(f"  latched after median {median(held) * 1000:.1f} ms, max {max(held) * 1000:.1f} ms", flush=True)
        print("estop mid-translation of a long task ...", flush=True)
        translation, still = bench_estop_mid_translation(daemon, args.translations)
        print(f"  final after median {median(translation):.3f} s, max {max(translation):.3f} s; "
              f"robot still every time: {all(still)}", flush=True)
        daemon.stop()
    finally:
        if daemon.process is not None and daemon.process.poll() is None:
            daemon.stop()
        shutil.rmtree(workdir, ignore_errors=True)

    results = {
        "benchmark": "hostile",
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "python": platform.python_version(),
            "load_average_at_end": round(os.getloadavg()[0], 2),
        },
        "fuzz": fuzz,
        "estop_all_slots_held_s": {
            "median": round(median(held), 4),
            "max": round(max(held), 4),
            "samples": [round(t, 4) for t in held],
        },
        "estop_mid_translation_final_s": {
            "median": round(median(translation), 4),
            "max": round(max(translation), 4),
            "samples": [round(t, 4) for t in translation],
            "robot_never_moved": all(still),
        },
        "targets": TARGETS,
        "met": {
            "fuzz": fuzz["dropped"] == 0 and fuzz["internal"] == 0 and fuzz["open_audit_records"] == 0,
            "estop_all_slots_held": max(held) <= TARGETS["estop_all_slots_held_max_s"],
            "estop_mid_translation": max(translation) <= TARGETS["estop_mid_translation_final_max_s"]
            and all(still),
        },
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=2, ensure_ascii=True) + "\n")
    print(json.dumps(results["met"], indent=2))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
