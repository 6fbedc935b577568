"""Start-up and shutdown shared by the nodes: loopback environment, a clear message and exit code 2 when the node
cannot start, a clean shutdown on Ctrl-C, SIGTERM or SIGHUP, or when the supervisor that started the node is gone
(`supervisor.watch_lifeline`).

rclpy's own signal handler would invalidate the context at once, while callbacks may still be running in the
executor's threads (their publishes then fail: "publisher's context is invalid"). Here a signal only ends the spin
loop; then the node is told to stop publishing (`begin_shutdown`), `on_exit` releases what it holds (the planner
node's campaign waits for observations being stored and a running optimization: rclpy's `Executor.shutdown` does
not wait for callbacks), and only then are the node and the context shut down. A second signal stops the waiting.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

import rclpy
import yaml
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from ..planner import GryffinRosError
from .rosenv import apply_to_this_process
from .supervisor import watch_lifeline

# How often the spin loop looks at the stop flag (the longest a signal waits to be noticed).
STOP_POLL_S = 0.1
# At shutdown the executor spins on while running work stops (at most DRAIN_S; an ask stops at its next checkpoint,
# well under a second), then DRAIN_AFTER_S more so that the results of aborted goals reach their clients.
DRAIN_S = 3.0
DRAIN_AFTER_S = 0.3
_TYPE_NAMES = {bool: "true or false", int: "an integer", float: "a number", str: "a string", list: "a list"}


def declare(node: Node, parameters: dict[str, tuple[Any, str]], read_only: tuple[str, ...] = ()
            ) -> dict[str, Any]:
    """Declare the node's parameters (name: (default, description)) and return their values; those in `read_only`
    refuse a set at run time. A value of the wrong type (`-p batch_size:=three`) is a GryffinRosError saying what
    is expected, not rclpy's traceback."""
    values = {}
    for name, (default, description) in parameters.items():
        try:
            node.declare_parameter(name, default, ParameterDescriptor(description=description,
                                                                      read_only=name in read_only))
        except InvalidParameterTypeException:
            expected = _TYPE_NAMES.get(type(default), type(default).__name__)
            raise GryffinRosError(f"parameter '{name}' must be {expected} ({description}); default "
                                  f"{default!r}") from None
        values[name] = node.get_parameter(name).value
    return values


def unreadable_parameter(args: list[str]) -> str | None:
    """Why a `-p name:=value` of these arguments would stop rcl's argument parser (which reads each value as YAML and
    says only "Unknown YAML event" for one it cannot take, such as `:memory:`, a mapping to YAML), or None."""
    for flag, argument in zip(args, args[1:]):
        if flag not in ("-p", "--param") or ":=" not in argument:
            continue
        name, value = argument.split(":=", 1)
        try:
            parsed = yaml.safe_load(value)
        except yaml.YAMLError:
            parsed = {}
        if isinstance(parsed, dict):
            return (f"parameter '{name}': ROS reads the value {value!r} as YAML and cannot take it; quote it: "
                    f"-p \"{name}:='{value}'\"")
    return None


def environment_line() -> str:
    """What a lab client must match to see this node: domain, RMW, discovery range."""
    return (f"ROS_DOMAIN_ID={os.environ.get('ROS_DOMAIN_ID', '0 (unset: the ROS default)')}, "
            f"RMW_IMPLEMENTATION={os.environ.get('RMW_IMPLEMENTATION', 'default')}, "
            f"ROS_AUTOMATIC_DISCOVERY_RANGE={os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE', 'default')}"
            + (f", ROS_STATIC_PEERS={os.environ['ROS_STATIC_PEERS']}" if os.environ.get("ROS_STATIC_PEERS") else ""))


def drain(spinner: Executor, node: Node) -> None:
    """Spin on, at most DRAIN_S, while the node finishes what it was stopping (a Recommend goal aborted with its
    reason: its result goes to the client only while the executor spins), and DRAIN_AFTER_S more for the answers."""
    deadline = time.monotonic() + DRAIN_S
    settled = getattr(node, "settled", lambda: True)
    if settled():
        return  # nothing was running: nothing to deliver
    while not settled() and time.monotonic() < deadline:
        spinner.spin_once(timeout_sec=0.05)
    until = min(deadline, time.monotonic() + DRAIN_AFTER_S)
    while time.monotonic() < until:
        spinner.spin_once(timeout_sec=0.05)


def run(make_node: Callable[[], Node], label: str, args: list[str] | None = None,
        executor: Callable[[], Executor] = SingleThreadedExecutor,
        on_exit: Callable[[Node], None] | None = None) -> int:
    apply_to_this_process()
    unreadable = unreadable_parameter(sys.argv[1:] if args is None else args)
    if unreadable:
        print(f"{label}: cannot start: {unreadable}", file=sys.stderr)
        return 2
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    stop = threading.Event()

    def on_signal(*_: object) -> None:
        if stop.is_set():  # a second signal: stop waiting for what is still running
            raise KeyboardInterrupt
        stop.set()

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    watch_lifeline(stop.set)  # started by a Supervisor: stop when it is gone, however it ended
    try:
        try:
            node = make_node()
        except GryffinRosError as exc:
            print(f"{label}: cannot start: {exc}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            return 130
        node.get_logger().info(environment_line())
        spinner = executor()
        spinner.add_node(node)
        try:
            while not stop.is_set() and rclpy.ok():
                spinner.spin_once(timeout_sec=STOP_POLL_S)
        except (KeyboardInterrupt, ExternalShutdownException):
            pass
        try:
            if hasattr(node, "begin_shutdown"):
                node.begin_shutdown()
                drain(spinner, node)
            spinner.shutdown()
            if on_exit is not None:
                on_exit(node)  # may wait for a running optimization to write its results
            node.destroy_node()
        except KeyboardInterrupt:
            print(f"{label}: stopped on a second signal, without waiting for running callbacks (what was "
                  "acknowledged is stored)", file=sys.stderr)
            return 130
        return 0
    finally:
        rclpy.try_shutdown()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
