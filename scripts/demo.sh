#!/usr/bin/env bash
# Install nrtrans into ./.venv and run the main job on the embedded defaults:
# the simulator and the bundled model.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install.sh
exec .venv/bin/nrtrans demo "$@"
