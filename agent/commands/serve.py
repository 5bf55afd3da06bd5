"""`nrtrans serve`: run the daemon."""

from __future__ import annotations

import argparse
import logging
import os
import sys
from typing import Any


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "serve",
        help="run the daemon: socket API, speech input, translation and the robot",
        description=(
            "Run the nrtrans daemon. It loads the config, the robot profile, the model and the "
            "backend, then serves the local socket API until SIGTERM. Under systemd it reports "
            "readiness (READY=1), status and watchdog pings via $NOTIFY_SOCKET. SIGHUP reloads "
            "the config file."
        ),
        epilog="Settings and their defaults: docs/config.md (or --print-config).",
    )
    parser.add_argument(
        "--config", metavar="FILE", help="config file (TOML); default: $NRTRANS_CONFIG, else built-in defaults"
    )
    parser.add_argument(
        "--socket", metavar="PATH", help="Unix socket path (default: $NRTRANS_SOCKET, else api.socket)"
    )
    parser.add_argument("--state-dir", metavar="DIR", help="audit log directory (overrides state_dir)")
    parser.add_argument("--backend", choices=("sim", "ros2"), help="robot backend (overrides robot.backend)")
    parser.add_argument(
        "--print-config", action="store_true", help="print a config file with every setting at its default, and exit"
    )
    parser.add_argument("--config-doc", action="store_true", help="print docs/config.md and exit")
    parser.add_argument(
        "--api-doc", action="store_true", help="print the generated schema part of docs/api.md and exit"
    )
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from agent.daemon import config as config_module

    if args.print_config:
        print(config_module.render_toml(), end="")
        return 0
    if args.config_doc:
        print(config_module.render_markdown(), end="")
        return 0
    if args.api_doc:
        from agent.daemon.schemas import render_markdown

        print(render_markdown(), end="")
        return 0

    from agent.daemon.runner import reloader, serve

    config_file = config_module.config_path_from_env(args.config)
    # The socket is found in the same order as the client commands look for it (agent.client.find_socket).
    socket = args.socket or os.environ.get("NRTRANS_SOCKET")
    overrides = {"socket": socket, "state_dir": args.state_dir, "backend": args.backend}
    try:
        config = config_module.load_config(config_file).with_overrides(**overrides)
    except config_module.ConfigError as exc:
        print(f"nrtrans serve: error: {exc}", file=sys.stderr)
        return 2
    logging.basicConfig(level=config.log_level.upper(), stream=sys.stderr, format="%(levelname)s %(name)s: %(message)s")
    return serve(config, config_file=config_file, reload=reloader(config_file, overrides))
