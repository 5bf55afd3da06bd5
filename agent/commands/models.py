"""`nrtrans models list|fetch|path|verify`: the models in the manifest."""

from __future__ import annotations

import argparse
import sys
from typing import Any

DESCRIPTION = """\
Manage the models nrtrans uses: the LLM that writes programs and the Vosk
speech recogniser. Models are named in models/manifest.toml and stored in the
model directory ($NRTRANS_MODEL_DIR, else $STATE_DIRECTORY/models, else
~/.local/share/nrtrans/models). Nothing is downloaded unless you run `fetch`.
"""


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "models", help="list, fetch and verify LLM and speech models",
        description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="models_command", metavar="ACTION", required=True)

    listing = commands.add_parser("list", help="show every known model and whether it is on this machine",
                                  description="Show every model in the manifest, its size, licence and "
                                              "whether it is on this machine.")
    listing.set_defaults(func=_list)

    fetch = commands.add_parser(
        "fetch", help="download a model (resumes, verifies sha256, unpacks)",
        description="Download a model with a progress bar. An interrupted download resumes from its .part "
                    "file on the next run; the file is kept only when its sha256 matches the manifest; "
                    "zip archives are unpacked. Set HF_TOKEN for gated Hugging Face models.",
        epilog="example: nrtrans models fetch vosk-model-small-en-us-0.15")
    fetch.add_argument("name", metavar="NAME", help="a model name from `nrtrans models list`")
    fetch.add_argument("--url", help="download from this URL instead of the manifest's (a mirror)")
    fetch.add_argument("--sha256", help="expect this checksum (when the manifest pins none, or to override)")
    fetch.add_argument("--timeout", type=float, default=30.0,
                       help="seconds to wait for the server (default 30)")
    fetch.set_defaults(func=_fetch)

    path = commands.add_parser("path", help="print where a model is, if it is usable",
                               description="Print the file or directory of a usable model; exit 1 with the "
                                           "reason when it is not fetched or not verified.")
    path.add_argument("name", metavar="NAME", help="a model name from `nrtrans models list`")
    path.set_defaults(func=_path)

    verify = commands.add_parser(
        "verify", help="check a fetched or hand-copied model against its sha256",
        description="Hash a model file in the model directory (for example one you copied from another "
                    "machine) against the manifest, unpack it if it is an archive, and mark it usable.")
    verify.add_argument("name", metavar="NAME", help="a model name from `nrtrans models list`")
    verify.add_argument("--sha256", help="expect this checksum instead of the manifest's")
    verify.set_defaults(func=_verify)


def _list(args: argparse.Namespace) -> int:
    from models.store import installed_path, is_verified, load_manifest, model_dir

    print(f"model directory: {model_dir()}")
    rows = [("NAME", "KIND", "STATE", "DESCRIPTION")]
    for entry in load_manifest():
        if entry.source == "python-package":
            state = "pip package"
        elif is_verified(entry):
            state = "fetched"
        elif installed_path(entry).exists() or (model_dir() / entry.file).exists():
            state = "unverified"
        else:
            state = "not fetched"
        name = entry.name + (" *" if entry.default else "")
        rows.append((name, entry.kind, state, entry.description))
    widths = [max(len(row[i]) for row in rows) for i in range(3)]
    for row in rows:
        print("  ".join(cell.ljust(width) for cell, width in zip(row[:3], widths, strict=True)), row[3])
    print("* = default for its kind")
    return 0


def _fetch(args: argparse.Namespace) -> int:
    from models.fetch import fetch
    from models.store import ModelError, require_entry

    try:
        entry = require_entry(args.name)
        result = fetch(entry, url=args.url, sha256=args.sha256, timeout=args.timeout)
    except ModelError as exc:
        print(f"nrtrans models fetch: {exc}", file=sys.stderr)
        return 1
    if result.already_present:
        print(f"{entry.name} is already here: {result.path}", file=sys.stderr)
    elif result.resumed_from:
        print(f"resumed {entry.name} from {result.resumed_from / 2**20:.1f} MB", file=sys.stderr)
    _warn_unpinned(result.pinned, entry.name, result.sha256)
    print(result.path)
    return 0


def _path(args: argparse.Namespace) -> int:
    from models.store import ModelError, require_entry, resolve_llm, resolve_vosk

    try:
        entry = require_entry(args.name)
        path = resolve_llm(entry.name) if entry.kind == "llm" else resolve_vosk(entry.name)
    except ModelError as exc:
        print(f"nrtrans models path: {exc}", file=sys.stderr)
        return 1
    print(path)
    return 0


def _verify(args: argparse.Namespace) -> int:
    from models.fetch import verify
    from models.store import ModelError, require_entry

    try:
        entry = require_entry(args.name)
        result = verify(entry, sha256=args.sha256)
    except ModelError as exc:
        print(f"nrtrans models verify: {exc}", file=sys.stderr)
        return 1
    _warn_unpinned(result.pinned, entry.name, result.sha256)
    print(f"ok: {result.path}")
    return 0


def _warn_unpinned(pinned: bool, name: str, sha256: str) -> None:
    if not pinned and sha256:
        print(f"warning: the manifest pins no checksum for `{name}`, so this file could not be checked. "
              f"Its sha256 is {sha256}; compare it with the one the publisher shows before trusting it.",
              file=sys.stderr)
