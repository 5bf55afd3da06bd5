"""The ROS 2 side of nrtrans: a robot backend over standard topics and services,
and a bridge that serves the pybullet simulator over the same interfaces.

Nothing here imports rclpy at package import time, so the rest of nrtrans
works on machines without ROS 2.
"""
