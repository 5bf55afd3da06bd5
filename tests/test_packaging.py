"""pyproject.toml and scripts/test.sh: an SPDX licence, both ROS 2 distributions installable and tested."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]


def test_the_licence_is_an_spdx_string() -> None:
    # A `license = { text = ... }` table makes setuptools warn on every install.
    assert PROJECT["license"] == "Apache-2.0"


def test_jazzy_and_kilted_extras_hold_the_same_packages() -> None:
    extras = PROJECT["optional-dependencies"]
    kilted = {name.removeprefix("ros-") for name in extras["ros"]}
    jazzy = {name.removeprefix("ros-jazzy-") for name in extras["ros-jazzy"]}
    assert kilted == jazzy, kilted ^ jazzy
    assert not any(name.startswith("nrtrans[ros") for name in extras["test"])  # one distribution per venv


def test_the_test_command_runs_the_ros2_tests_on_jazzy_too() -> None:
    script = (ROOT / "scripts" / "test.sh").read_text(encoding="utf-8")
    assert "scripts/install.sh --venv .venv-jazzy test,ros-jazzy" in script
    jazzy_run = re.search(r"NRTRANS_ROS_DISTRO=jazzy \.venv-jazzy/bin/pytest \\\n\s+(.+?) \|\|", script)
    assert jazzy_run, script
    paths = jazzy_run.group(1).split()
    assert "tests/ros2" in paths
    assert all((ROOT / path).exists() for path in paths), paths
    assert ".venv-jazzy/" in (ROOT / ".gitignore").read_text(encoding="utf-8").splitlines()
