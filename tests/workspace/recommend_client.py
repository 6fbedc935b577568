"""A lab client run in a colcon workspace's environment (after `source install/setup.bash`): it probes the planner's
~/get_status, sends one typed Recommend goal (under an instrument name, resent while its acceptance or result is lost:
the client rules of docs/ros.md) and prints, as one JSON line, the proposals and where it imported the packages from.

    python recommend_client.py COUNT TIMEOUT_S
"""

from __future__ import annotations

import json
import sys
import threading
import time

import gryffin_ros_msgs
import rclpy
from gryffin_ros_msgs.action import Recommend
from gryffin_ros_msgs.srv import GetStatus
from rclpy.action import ActionClient
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

import gryffin_ros

RESEND_S, RESULT_RESEND_S = 5.0, 30.0


def wait(future, seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while not future.done() and time.monotonic() < deadline:
        time.sleep(0.02)
    return future.done()


def main() -> int:
    count, timeout = int(sys.argv[1]), float(sys.argv[2])
    deadline = time.monotonic() + timeout
    rclpy.init()
    node = Node("workspace_lab_client")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin)
    spinner.start()
    action = None
    try:
        status = node.create_client(GetStatus, "/gryffin_planner/get_status")
        while not (status.wait_for_service(timeout_sec=2.0) and wait(status.call_async(GetStatus.Request()), 2.0)):
            if time.monotonic() > deadline:
                raise SystemExit("the planner's ~/get_status never answered")
        action = ActionClient(node, Recommend, "/gryffin_planner/recommend")
        while True:
            if time.monotonic() > deadline:
                raise SystemExit("no Recommend result")
            if not action.wait_for_server(timeout_sec=2.0):
                continue
            accepted = action.send_goal_async(Recommend.Goal(count=count, instrument="workspace_lab"))
            if not wait(accepted, RESEND_S):
                continue
            goal = accepted.result()
            if not goal.accepted:
                raise SystemExit("Recommend goal rejected")
            result = goal.get_result_async()
            if wait(result, RESULT_RESEND_S):
                break
        answer = result.result().result
        print(json.dumps({
            "gryffin_ros": gryffin_ros.__file__, "gryffin_ros_msgs": gryffin_ros_msgs.__file__,
            "error": answer.error, "n_observations": answer.n_observations,
            "proposals": [{"experiment_id": p.experiment_id,
                           "params": {v.name: v.text or v.number for v in p.params}} for p in answer.proposals],
        }), flush=True)
        return 0
    finally:
        executor.shutdown()
        spinner.join()
        if action is not None:
            action.destroy()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
