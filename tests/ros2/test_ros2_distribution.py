"""The ROS 2 tests run on the distribution scripts/test.sh meant (Kilted in .venv, Jazzy in .venv-jazzy)."""

from __future__ import annotations

import os
from importlib import metadata

import pytest


def _installed_distribution() -> str:
    # The Jazzy wheels come with a `ros-jazzy-` meta-package; Kilted's are the plain `ros-` ones.
    try:
        metadata.version("ros-jazzy-rclpy")
    except metadata.PackageNotFoundError:
        return "kilted"
    return "jazzy"


def test_the_ros2_wheels_are_the_distribution_under_test() -> None:
    expected = os.environ.get("NRTRANS_ROS_DISTRO")
    if not expected:
        pytest.skip("NRTRANS_ROS_DISTRO is not set; scripts/test.sh sets it for each venv")
    import rclpy

    assert _installed_distribution() == expected, f"rclpy {metadata.version('rclpy')} from {rclpy.__file__}"
