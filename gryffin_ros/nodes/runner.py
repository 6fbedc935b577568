"""Start-up and shutdown shared by the nodes: loopback environment, a clear message and exit code 2 when the node
cannot start, a clean shutdown on Ctrl-C or SIGTERM."""

from __future__ import annotations

import sys
from collections.abc import Callable

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node

from ..planner import GryffinRosError
from ..rosenv import apply_to_this_process


def run(make_node: Callable[[], Node], label: str, args: list[str] | None = None,
        executor: Callable[[], Executor] = SingleThreadedExecutor,
        on_exit: Callable[[Node], None] | None = None) -> int:
    apply_to_this_process()
    rclpy.init(args=args)
    try:
        node = make_node()
    except GryffinRosError as exc:
        print(f"{label}: cannot start: {exc}", file=sys.stderr)
        rclpy.try_shutdown()
        return 2
    spinner = executor()
    spinner.add_node(node)
    try:
        spinner.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        spinner.shutdown()
        if on_exit is not None:
            on_exit(node)
        node.destroy_node()
        rclpy.try_shutdown()
    return 0
