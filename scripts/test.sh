#!/usr/bin/env bash
# Install nrtrans with its test extras and run ruff, mypy and the whole suite.
#
# Two venvs, one per ROS 2 distribution from PyPI: ./.venv (ROS 2 Kilted, plus the
# `train` extra, ~2.4 GB with the CPU build of torch, for the adapter training test)
# runs everything; ./.venv-jazzy (ROS 2 Jazzy, the LTS) runs the ROS 2 tests again.
# With arguments, they go to the main pytest run and the Jazzy pass is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install.sh test,ros,train
.venv/bin/ruff check .
.venv/bin/mypy

status=0
if (($# == 0)); then
  scripts/install.sh --venv .venv-jazzy test,ros-jazzy
  echo "== the ROS 2 tests on ROS 2 Jazzy (.venv-jazzy); the whole suite on Kilted follows" >&2
  NRTRANS_ROS_DISTRO=jazzy .venv-jazzy/bin/pytest \
    tests/ros2 tests/daemon/test_daemon_ros2.py tests/sim/test_sim_dry_run_ros2.py || status=$?
fi
NRTRANS_ROS_DISTRO=kilted .venv/bin/pytest "$@" || status=$?
exit "$status"
