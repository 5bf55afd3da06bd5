"""The daemon on the ROS 2 backend, with `nrtrans sim-bridge` as the robot over loopback DDS."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

from tests.daemon.conftest import NRTRANS, Daemon, follow


def test_dead_robot_link_fails_the_task_and_the_daemon_keeps_serving(workdir: Path) -> None:
    ros_env = {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_DOMAIN_ID": str(150 + os.getpid() % 80),
        "ROS_LOG_DIR": str(workdir / "ros-log"),
    }
    with open(workdir / "bridge.log", "wb") as log:
        bridge = subprocess.Popen(
            [NRTRANS, "sim-bridge"], env={**os.environ, **ros_env}, stdout=log, stderr=subprocess.STDOUT
        )
    daemon = Daemon(workdir, {"robot": {"backend": "ros2"}}, extra_env=ros_env)
    try:
        daemon.start()
        with daemon.client(timeout=120) as client:
            task = client.submit(rsl="forward 0.3;", follow=True)
            assert follow(client, task)[-1]["event"] == "done", daemon.output()

            task = client.submit(rsl="forward 4;", follow=True)
            for event in client.events():
                if event["event"] == "executing":
                    break
            time.sleep(0.5)
            bridge.send_signal(signal.SIGKILL)
            bridge.wait(30)
            started = time.monotonic()
            last = follow(client, task, timeout=60)[-1]
            assert last["event"] == "failed", last
            assert time.monotonic() - started < 10, "a dead link is noticed within seconds"
            assert last["reason"], "the failure says why"
            assert client.status()["state"] == "idle"
            record = client.status(task)
            assert record["steps"][-1]["outcome"]["status"] == "failed"
    finally:
        if bridge.poll() is None:
            bridge.kill()
            bridge.wait(30)
        assert daemon.stop() == 0, daemon.output()
