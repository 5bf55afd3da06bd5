"""Checks that take milliseconds, run before the model takes seconds to load.

A socket or state directory the daemon cannot create would otherwise fail
only after the model has loaded. Each problem is one line: what, where, and
what to do.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from agent.daemon.config import Config

# sun_path holds 108 bytes, the last one a NUL.
_MAX_SOCKET_PATH = 107


def startup_problems(config: Config, *, socket_activated: bool) -> list[str]:
    problems = []
    if not socket_activated:
        problems += _socket_problems(config.socket_path())
    state = config.state_path()
    where = _directory_problem(state)
    if where:
        problems.append(f"the state directory {state} {where}; make it writable, or choose another with --state-dir")
    else:
        audit = config.audit_path()
        if audit.exists() and (not audit.is_file() or not os.access(audit, os.R_OK | os.W_OK)):
            problems.append(
                f"the audit log {audit} is not a file this user can read and write; fix its owner or mode"
            )
    return problems


def _socket_problems(path: Path) -> list[str]:
    fix = "choose another path with --socket (or api.socket)"
    if len(os.fsencode(path)) > _MAX_SOCKET_PATH:
        return [f"the socket path {path} is longer than {_MAX_SOCKET_PATH} bytes, the limit for a Unix socket; {fix}"]
    where = _directory_problem(path.parent)
    if where:
        return [f"the socket directory {path.parent} {where}; {fix}"]
    if path.is_symlink() or (path.exists() and not stat.S_ISSOCK(path.stat().st_mode)):
        return [f"{path} exists and is not a socket; remove it or {fix}"]
    return []


def _directory_problem(path: Path) -> str:
    """Why `path` cannot be used (or created) as a writable directory; "" when it can."""
    existing = path
    while not existing.exists():
        if existing.is_symlink():
            return f"cannot be created: {existing} is a broken symbolic link"
        existing = existing.parent
    if not existing.is_dir():
        return f"cannot be created: {existing} is not a directory" if existing != path else "is not a directory"
    if not os.access(existing, os.W_OK | os.X_OK):
        return (
            f"cannot be created: {existing} is not writable by this user"
            if existing != path
            else "is not writable by this user"
        )
    return ""
