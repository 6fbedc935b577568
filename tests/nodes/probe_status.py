"""`python -m tests.nodes.probe_status [NODE] [DEADLINE_S]`: ask a planner's ~/get_status from a process of its own (a
DDS participant of its own), sending again every QUERY_RESEND_S until an answer comes or the deadline passes; prints
"answered" or "no answer" and exits 0 either way. A test whose own process gets no answer from a planner runs it to
tell a planner that answers nobody from a test process that lost it (tests/nodes/conftest.py, `why_unanswered`)."""

from __future__ import annotations

import os
import sys
import time

from gryffin_ros.nodes.rosenv import ros_environment

os.environ.update(ros_environment())  # before rclpy is initialized

import rclpy  # noqa: E402
from gryffin_ros_msgs.srv import GetStatus  # noqa: E402

QUERY_RESEND_S = 2.0


def main(node: str = "/gryffin_planner", deadline_s: float = 30.0) -> str:
    rclpy.init()
    probe = rclpy.create_node("status_probe")
    try:
        client = probe.create_client(GetStatus, f"{node}/get_status")
        deadline = time.monotonic() + deadline_s
        while time.monotonic() < deadline:
            if not client.wait_for_service(timeout_sec=QUERY_RESEND_S):
                continue
            future = client.call_async(GetStatus.Request())
            rclpy.spin_until_future_complete(probe, future, timeout_sec=QUERY_RESEND_S)
            if future.done():
                return "answered"
            client.remove_pending_request(future)
        return "no answer"
    finally:
        probe.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    print(main(*sys.argv[1:2], *(float(a) for a in sys.argv[2:3])), flush=True)
