#!/usr/bin/env bash
# Install nrtrans with its test extras into ./.venv and run the whole suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install.sh test,train
.venv/bin/ruff check .
.venv/bin/mypy
exec .venv/bin/pytest "$@"
