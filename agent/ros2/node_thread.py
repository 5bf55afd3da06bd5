"""One rclpy node with its own context and executor, spinning in a daemon thread.

The backend lives inside the nrtrans daemon next to other code, so it must not
touch rclpy's global context or install signal handlers: the daemon owns
SIGINT and SIGTERM and decides how to stop the robot.
"""

from __future__ import annotations

import contextlib
import threading
from typing import Any


class NodeThread:
    def __init__(self, name: str) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.signals import SignalHandlerOptions

        self.context = Context()
        rclpy.init(context=self.context, signal_handler_options=SignalHandlerOptions.NO)
        try:
            self.node: Any = Node(name, context=self.context)
        except Exception:
            rclpy.try_shutdown(context=self.context)
            raise
        self._executor = SingleThreadedExecutor(context=self.context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name=f"rclpy-{name}", daemon=True)
        self._thread.start()
        self._closed = False

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        with contextlib.suppress(ExternalShutdownException):
            self._executor.spin()

    def close(self) -> None:
        import rclpy

        if self._closed:
            return
        self._closed = True
        self._executor.shutdown(timeout_sec=2.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        self._thread.join(timeout=2.0)
