"""Latency of the planner node over ROS 2 on loopback: ~/recommend round trip, observation -> event, and the wall
time of a 30-experiment closed-loop flow-reactor campaign (emulator experiment time 0).

    python benchmarks/ros_latency.py [--calls 20] [--out benchmarks/results/ros_latency.md]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from gryffin_ros.paths import share_path
from gryffin_ros.rosenv import ros_environment

os.environ.update(ros_environment())

import rclpy  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from gryffin_ros.nodes.qos import EVENTS_QOS, OBSERVATIONS_QOS  # noqa: E402


def call(client, timeout: float = 60.0):
    future = client.call_async(Trigger.Request())
    done = threading.Event()
    future.add_done_callback(lambda _: done.set())
    if not done.wait(timeout):
        raise TimeoutError(client.srv_name)
    return future.result()


def node_latencies(calls: int, workdir: Path) -> tuple[list[float], list[float]]:
    config = share_path("examples") / "flow_reactor.yaml"
    planner = subprocess.Popen([sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-p",
                                f"config:={config}", "-p", f"storage:={workdir / 'bench.sqlite'}", "-p", "seed:=0",
                                "-p", "auto_propose:=false"], env={**os.environ, "ROS_LOG_DIR": str(workdir)},
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rclpy.init()
    node = rclpy.create_node("bench_client")
    events: dict[str, float] = {}
    arrived = threading.Event()

    def on_event(msg: String) -> None:
        events.setdefault(json.loads(msg.data).get("experiment_id", ""), time.perf_counter())
        arrived.set()
    node.create_subscription(String, "/gryffin_planner/events", on_event, EVENTS_QOS)
    publisher = node.create_publisher(String, "/gryffin_planner/observations", OBSERVATIONS_QOS)
    recommend = node.create_client(Trigger, "/gryffin_planner/recommend")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    try:
        if not recommend.wait_for_service(timeout_sec=60):
            raise TimeoutError("planner node did not start")
        while publisher.get_subscription_count() == 0:
            time.sleep(0.01)
        round_trips, to_event = [], []
        for i in range(calls):
            start = time.perf_counter()
            response = call(recommend)
            round_trips.append(time.perf_counter() - start)
            proposal = json.loads(response.message)["proposals"][0]
            sent = time.perf_counter()
            publisher.publish(String(data=json.dumps({"experiment_id": proposal["experiment_id"],
                                                      "params": proposal["params"],
                                                      "objectives": {"X1_X2": 0.5 + 0.01 * i, "cost": 0.01}})))
            while proposal["experiment_id"] not in events:
                arrived.wait(timeout=1.0)
                arrived.clear()
            to_event.append(events[proposal["experiment_id"]] - sent)
        return round_trips, to_event
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
        planner.send_signal(signal.SIGINT)
        planner.wait(timeout=30)


def closed_loop_seconds(workdir: Path) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "gryffin_ros.cli", "campaign", "--budget", "30", "--seed", "0", "--out",
                    str(workdir / "loop")], check=True, capture_output=True, env=dict(os.environ))
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--calls", type=int, default=20)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "ros_latency.md")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        round_trips, to_event = node_latencies(args.calls, workdir)
        loop = closed_loop_seconds(workdir)
    def ms(values: list[float]) -> str:
        return f"{1000 * statistics.median(values):.1f} ms (max {1000 * max(values):.1f} ms)"
    text = (f"Planner node over ROS 2 (Fast DDS, loopback), {args.calls} calls, flow-reactor config, 2 cores:\n\n"
            f"| measure | median |\n|---|---|\n"
            f"| `~/recommend` round trip (includes one ask) | {ms(round_trips)} |\n"
            f"| observation published -> `observation_accepted` event received | {ms(to_event)} |\n"
            f"| 30-experiment closed loop, `gryffin-ros campaign --budget 30` (both nodes started) | {loop:.1f} s |\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
