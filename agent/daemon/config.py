"""The daemon's settings: one TOML file, every setting with a default.

The dataclasses below are the single source of truth: `load_config` reads
them (through rsl/settings.py, which checks each value against its field's
type and metadata), `render_markdown` writes docs/config.md from them and
`render_toml` writes a commented example file, so the documentation cannot
drift from the code.
"""

from __future__ import annotations

import dataclasses
import os
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, get_type_hints

from rsl.settings import check_value, read_settings


class ConfigError(ValueError):
    """A configuration that cannot be used; the message says where and what to do."""


def _doc(text: str, **extra: Any) -> dict[str, Any]:
    return {"doc": text, **extra}


@dataclass(frozen=True)
class ApiConfig:
    socket: str = field(
        default="",
        metadata=_doc(
            "Path of the Unix socket. Empty: `$RUNTIME_DIRECTORY/nrtrans.sock`, else "
            "`$XDG_RUNTIME_DIR/nrtrans/nrtrans.sock`, else `/run/nrtrans/nrtrans.sock`."
        ),
    )
    socket_mode: str = field(
        default="0660", metadata=_doc("Permission bits of the socket file, as an octal string.", octal=True)
    )
    allowed_uids: tuple[int, ...] = field(
        default=(),
        metadata=_doc(
            "Peer user ids that may connect (checked with SO_PEERCRED). Empty, together with an "
            "empty `allowed_gids`: anyone who can open the socket file. The daemon's own uid is "
            "always allowed."
        ),
    )
    allowed_gids: tuple[int, ...] = field(
        default=(), metadata=_doc("Peer primary group ids that may connect (checked with SO_PEERCRED).")
    )
    max_line_bytes: int = field(
        default=65536,
        metadata=_doc(
            "Longest request frame, in bytes including the newline. A longer frame gets a "
            "`too_long` error and is skipped; the connection stays usable.",
            min=256,
        ),
    )
    max_task_chars: int = field(
        default=2000, metadata=_doc("Longest `text` task or `rsl` program a `submit` may carry, in characters.", min=1)
    )
    max_clients: int = field(
        default=128,
        metadata=_doc(
            "Most connections served at once. Past it a connection may still send one `estop` (an emergency "
            "stop is never locked out); anything else gets a `busy` error and is closed.",
            min=1,
        ),
    )
    client_queue: int = field(
        default=1024,
        metadata=_doc(
            "Most frames waiting to be sent to one client. A client that falls this far behind "
            "is disconnected, so a slow reader never holds up the others.",
            min=8,
        ),
    )


@dataclass(frozen=True)
class TasksConfig:
    queue_size: int = field(
        default=8,
        metadata=_doc(
            "Most tasks waiting behind the one in progress. A `submit` beyond it gets a `busy` "
            "error; nothing is dropped silently.",
            min=1,
        ),
    )
    history: int = field(default=200, metadata=_doc("Finished tasks kept in memory for `status`.", min=1))
    shutdown_grace: float = field(
        default=10.0,
        metadata=_doc(
            "Seconds SIGTERM waits for the task in progress to stop and its audit record to be "
            "written, after the robot has been stopped.",
            min=0.0,
        ),
    )


@dataclass(frozen=True)
class TranslatorConfig:
    model: str = field(
        default="",
        metadata=_doc(
            "GGUF model: a file path or a model name from `nrtrans models list`. "
            "Empty: the embedded Gemma 3 270M model."
        ),
    )
    adapter: str = field(
        default="",
        metadata=_doc(
            "LoRA adapter GGUF file, or `none`. Empty: the adapter shipped for the embedded model, when there is one."
        ),
    )
    endpoint: str = field(
        default="",
        metadata=_doc(
            "Use a translation server at this address instead of loading the model in-process. Empty: in-process."
        ),
    )
    grammar: bool = field(
        default=True, metadata=_doc("Limit sampling to the RSL grammar generated from the robot profile.")
    )
    warmup: bool = field(
        default=True,
        metadata=_doc(
            "After READY=1, translate one example task from the robot profile in the background, "
            "so the first real task finds the model's prompt cache and token masks warm. A task "
            "submitted meanwhile waits for it."
        ),
    )
    max_passes: int = field(
        default=3,
        metadata=_doc("Most translation attempts per task (the first plus repairs from compiler diagnostics).", min=1),
    )
    confirm: str = field(
        default="unsure",
        metadata=_doc(
            "When to ask the person before a verified plan moves the robot: `unsure` when the "
            "translation's confidence is low or its meaning checks disagree with the task, `always`, "
            "or `never`. The question is a `confirm` event; a `confirm` request or a spoken yes/no "
            "answers it. Applies at once on SIGHUP.",
            choices=("never", "unsure", "always"),
        ),
    )
    confirm_timeout: float = field(
        default=20.0,
        metadata=_doc("Seconds to wait for an answer; with none the task is cancelled and nothing moves.", min=0.1),
    )


@dataclass(frozen=True)
class RobotConfig:
    profile: str = field(default="", metadata=_doc("Robot profile TOML. Empty: the built-in default profile."))
    backend: str = field(
        default="sim",
        metadata=_doc("Where verified programs run: `sim` (pybullet, headless) or `ros2`.", choices=("sim", "ros2")),
    )
    scene: str = field(default="", metadata=_doc("Simulator scene. Empty: the simulator's default scene."))
    realtime_factor: float = field(
        default=1.0, metadata=_doc("Simulator speed: 1.0 runs in real time, 0 as fast as possible.", min=0.0)
    )
    record: str = field(
        default="",
        metadata=_doc(
            "Directory for pictures of each task's run, in a folder named after the task: `trajectory.png`, "
            "and with the simulator a camera snapshot per step and `run.gif`. Empty: no pictures."
        ),
    )


@dataclass(frozen=True)
class AuditConfig:
    file: str = field(default="audit.jsonl", metadata=_doc("Audit log file name, relative to the state directory."))
    max_bytes: int = field(
        default=10_000_000,
        metadata=_doc(
            "Size at which the audit log is rotated (`audit.jsonl.1`, ...), checked between "
            "tasks so one task's record never spans two files.",
            min=1024,
        ),
    )
    keep: int = field(default=5, metadata=_doc("Rotated audit files kept.", min=0))


@dataclass(frozen=True)
class SpeechSection:
    enabled: bool = field(
        default=True,
        metadata=_doc(
            "Listen for spoken tasks. With no audio device or no model the daemon keeps serving "
            "the socket API and `health` says why speech is off."
        ),
    )
    options: dict[str, Any] = field(
        default_factory=dict,
        metadata=_doc(
            "Settings handed to the speech input unchanged (device, Vosk model path, wake word, "
            "...); see the speech section of the README."
        ),
    )


@dataclass(frozen=True)
class Config:
    state_dir: str = field(
        default="",
        metadata=_doc("Where the audit log lives. Empty: `$STATE_DIRECTORY`, else `~/.local/state/nrtrans`."),
    )
    log_level: str = field(
        default="info",
        metadata=_doc(
            "Log verbosity on stderr (the journal under systemd).", choices=("debug", "info", "warning", "error")
        ),
    )
    api: ApiConfig = field(default_factory=ApiConfig, metadata=_doc("The local socket API."))
    tasks: TasksConfig = field(default_factory=TasksConfig, metadata=_doc("The task queue."))
    translator: TranslatorConfig = field(default_factory=TranslatorConfig, metadata=_doc("Turning a task into RSL."))
    robot: RobotConfig = field(default_factory=RobotConfig, metadata=_doc("The robot and its backend."))
    audit: AuditConfig = field(default_factory=AuditConfig, metadata=_doc("The audit log."))
    speech: SpeechSection = field(default_factory=SpeechSection, metadata=_doc("Speech input."))

    def socket_path(self) -> Path:
        if self.api.socket:
            return Path(self.api.socket).expanduser()
        return runtime_dir() / "nrtrans.sock"

    def state_path(self) -> Path:
        if self.state_dir:
            return Path(self.state_dir).expanduser()
        if os.environ.get("STATE_DIRECTORY"):
            # systemd may pass several directories separated by colons; ours is the first.
            return Path(os.environ["STATE_DIRECTORY"].split(":")[0])
        return Path.home() / ".local" / "state" / "nrtrans"

    def audit_path(self) -> Path:
        return self.state_path() / self.audit.file

    def with_overrides(
        self, *, socket: str | None = None, state_dir: str | None = None, backend: str | None = None
    ) -> Config:
        config = self
        if socket:
            config = dataclasses.replace(config, api=dataclasses.replace(config.api, socket=socket))
        if state_dir:
            config = dataclasses.replace(config, state_dir=state_dir)
        if backend:
            check_value("robot.backend", str, backend, _meta(RobotConfig, "backend"), error=ConfigError)
            config = dataclasses.replace(config, robot=dataclasses.replace(config.robot, backend=backend))
        return config


def runtime_dir() -> Path:
    if os.environ.get("RUNTIME_DIRECTORY"):
        return Path(os.environ["RUNTIME_DIRECTORY"].split(":")[0])
    if os.environ.get("XDG_RUNTIME_DIR"):
        return Path(os.environ["XDG_RUNTIME_DIR"]) / "nrtrans"
    return Path("/run/nrtrans")


def config_path_from_env(flag: str | None) -> Path | None:
    chosen = flag or os.environ.get("NRTRANS_CONFIG")
    return Path(chosen).expanduser() if chosen else None


def load_config(path: str | Path | None) -> Config:
    """Read the config file; defaults everywhere when `path` is None."""
    if path is None:
        return Config()
    config_file = Path(path)
    try:
        text = config_file.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(
            f"cannot read config file {config_file}: {exc.strerror}\n"
            "  = help: pass an existing file with --config, or unset NRTRANS_CONFIG to use defaults"
        ) from exc
    return parse_config(text, source=str(config_file))


def parse_config(text: str, source: str = "<config>") -> Config:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: not valid TOML: {exc}") from exc
    return read_settings(Config, data, error=ConfigError, source=source, docs="docs/config.md")


def _meta(cls: type, name: str) -> dict[str, Any]:
    return dict(next(f for f in fields(cls) if f.name == name).metadata)


def _rows(cls: type, prefix: str) -> list[tuple[str, str, Any, str]]:
    rows = []
    hints = get_type_hints(cls)
    for f in fields(cls):
        hint = hints[f.name]
        if dataclasses.is_dataclass(hint):
            continue
        default = f.default_factory() if f.default_factory is not dataclasses.MISSING else f.default
        rows.append((prefix + f.name, _toml_value(default), hint, f.metadata["doc"]))
    return rows


def _sections() -> list[tuple[str, str, type]]:
    hints = get_type_hints(Config)
    return [
        (f.name, f.metadata["doc"], hints[f.name]) for f in fields(Config) if dataclasses.is_dataclass(hints[f.name])
    ]


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{}"
    return repr(value)


def render_markdown() -> str:
    """docs/config.md, generated from the dataclasses above."""
    lines = [
        "# nrtrans daemon configuration",
        "",
        "<!-- Generated by `nrtrans serve --config-doc`; edit agent/daemon/config.py instead. -->",
        "",
        "`nrtrans serve` reads one TOML file: `--config FILE`, else `$NRTRANS_CONFIG`, else",
        "built-in defaults. `--socket`, `--state-dir` and `--backend` override the file, and so",
        "does `$NRTRANS_SOCKET` when `--socket` is not given: the client commands look for the",
        "socket in the same order (`--socket`, `$NRTRANS_SOCKET`, `api.socket`, the default).",
        "SIGHUP re-reads the file: the API limits, allow-lists, queue and audit settings",
        "apply at once; the others (socket, state directory, model, profile, backend, speech)",
        "are reported and take effect on the next start. An unknown or mistyped setting is",
        "an error, never silently ignored. `nrtrans serve --print-config` prints a",
        "commented file with every default.",
        "",
        "## Top level",
        "",
    ]
    lines += _table(_rows(Config, ""))
    for name, doc, cls in _sections():
        lines += ["", f"## [{name}]", "", doc, ""]
        lines += _table(_rows(cls, ""))
    return "\n".join(lines) + "\n"


def _table(rows: list[tuple[str, str, Any, str]]) -> list[str]:
    out = ["| setting | default | meaning |", "|---|---|---|"]
    for key, default, _hint, doc in rows:
        out.append(f"| `{key}` | `{default}` | {doc} |")
    return out


def render_toml() -> str:
    """A complete example config file with every default, commented."""
    lines = ["# nrtrans daemon configuration; every value shown is the default.", ""]
    for key, default, _hint, doc in _rows(Config, ""):
        lines += [f"# {doc}", f"{key} = {default}", ""]
    for name, doc, cls in _sections():
        lines += [f"# {doc}", f"[{name}]"]
        for key, default, _hint, field_doc in _rows(cls, ""):
            if default == "{}":
                lines += [f"# {field_doc}", f"[{name}.{key}]", ""]
                continue
            lines += [f"# {field_doc}", f"{key} = {default}"]
        lines.append("")
    return "\n".join(lines)
