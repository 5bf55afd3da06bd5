"""Every command finds the daemon's socket the same way: --socket, $NRTRANS_SOCKET, the config, the default."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from agent.client import ClientError, find_socket
from tests.daemon.conftest import NRTRANS, Daemon


def _clean_env(monkeypatch: pytest.MonkeyPatch, **values: str) -> None:
    for name in ("NRTRANS_SOCKET", "NRTRANS_CONFIG", "RUNTIME_DIRECTORY", "XDG_RUNTIME_DIR"):
        monkeypatch.delenv(name, raising=False)
    for name, value in values.items():
        monkeypatch.setenv(name, value)


def test_the_lookup_order_is_flag_env_config_default(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    config = tmp_path / "config.toml"
    config.write_text('[api]\nsocket = "/tmp/from-config.sock"\n', encoding="utf-8")
    _clean_env(monkeypatch)
    assert find_socket() == Path("/run/nrtrans/nrtrans.sock")
    monkeypatch.setenv("XDG_RUNTIME_DIR", "/run/user/1000")
    assert find_socket() == Path("/run/user/1000/nrtrans/nrtrans.sock")
    monkeypatch.setenv("NRTRANS_CONFIG", str(config))
    assert find_socket() == Path("/tmp/from-config.sock")
    monkeypatch.delenv("NRTRANS_CONFIG")
    assert find_socket(config_file=config) == Path("/tmp/from-config.sock")
    monkeypatch.setenv("NRTRANS_SOCKET", "/tmp/from-env.sock")
    assert find_socket(config_file=config) == Path("/tmp/from-env.sock")
    assert find_socket("/tmp/from-flag.sock", config) == Path("/tmp/from-flag.sock")


def test_a_broken_config_is_a_clear_client_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _clean_env(monkeypatch)
    with pytest.raises(ClientError, match=r"cannot tell where the daemon listens.*missing\.toml"):
        find_socket(config_file=tmp_path / "missing.toml")


def _nrtrans(*args: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    base = {k: v for k, v in os.environ.items() if k not in ("NRTRANS_SOCKET", "NRTRANS_CONFIG")}
    return subprocess.run([NRTRANS, *args], capture_output=True, text=True, timeout=120, env={**base, **env})


def test_serve_and_the_clients_agree_on_the_socket(workdir: Path) -> None:
    """The README's commands: `export NRTRANS_SOCKET=...`, `nrtrans serve &`, then `nrtrans history`."""
    from_env = workdir / "env.sock"
    daemon = Daemon(workdir, extra_env={"NRTRANS_SOCKET": str(from_env)}).start()
    try:
        assert from_env.exists() and not daemon.socket.exists()  # the variable beat api.socket in the config
        history = _nrtrans("history", env={"NRTRANS_SOCKET": str(from_env)})
        assert history.returncode == 0, history.stderr
        assert history.stdout.strip() == "no tasks recorded yet"
        by_flag = _nrtrans("status", "--socket", str(from_env), "--config", str(daemon.config_file), env={})
        assert by_flag.returncode == 0 and by_flag.stdout.startswith("idle"), by_flag.stderr
        by_config = _nrtrans("history", env={"NRTRANS_CONFIG": str(daemon.config_file)})
        assert by_config.returncode == 2
        assert f"no daemon socket at {daemon.socket}" in by_config.stderr  # api.socket, where it did not listen
        env_beats_config = _nrtrans("history", "--config", str(daemon.config_file),
                                    env={"NRTRANS_SOCKET": str(from_env)})
        assert env_beats_config.returncode == 0, env_beats_config.stderr
    finally:
        daemon.stop()
