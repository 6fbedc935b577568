"""Load on the planner node over ROS 2 (loopback): (a) 1000 valid observations in a burst (accept_unsolicited), as
one list message and as 1000 single messages, timed until all are stored; (b) 50 concurrent ~/json/recommend calls;
(c) ~/json/get_status latency while the optimizer works.

    python -m benchmarks.load [--out benchmarks/results/load.md]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sqlite3
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import yaml

from gryffin_ros.nodes.rosenv import ros_environment

os.environ.update(ros_environment())

import rclpy  # noqa: E402
from rclpy.executors import MultiThreadedExecutor  # noqa: E402
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from gryffin_ros.nodes.supervisor import Supervisor, signals_as_interrupt  # noqa: E402

# every node this benchmark starts: stopped when it ends or is stopped (SIGINT, SIGTERM, SIGHUP), and gone by
# itself when this process is killed
NODES = Supervisor(stop_timeout_s=120.0)

CONFIG = {
    "name": "load",
    "parameters": [{"name": "F_C", "type": "continuous", "low": 0.0, "high": 200.0},
                   {"name": "F_S", "type": "continuous", "low": 0.0, "high": 200.0},
                   {"name": "T", "type": "continuous", "low": 100.0, "high": 150.0}],
    "objectives": [{"name": "X1_X2", "goal": "max"}],
    "constraints": [{"plugin": "flow_reactor"}],
}
# the lab side keeps every message until the planner acknowledged it (a burst larger than any fixed depth)
KEEP_ALL = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


def observations(n: int, prefix: str, rng: np.random.Generator) -> list[dict]:
    out = []
    while len(out) < n:
        fc, fs, t = rng.uniform(20, 180), rng.uniform(20, 180), rng.uniform(100, 150)
        if 30 < fc + fs < 310 and fc < 2 * fs and fs < 2 * fc:
            out.append({"experiment_id": f"{prefix}-{len(out)}", "params": {"F_C": fc, "F_S": fs, "T": t},
                        "objectives": {"X1_X2": float(rng.random())}})
    return out


def count(store: Path) -> int:
    with sqlite3.connect(store) as db:
        return db.execute("SELECT COUNT(*) FROM observations").fetchone()[0]


def wait_stored(store: Path, n: int, timeout: float = 300.0) -> float:
    start = time.perf_counter()
    while count(store) < n:
        if time.perf_counter() - start > timeout:
            return float("nan")
        time.sleep(0.01)
    return time.perf_counter() - start


def call(client, timeout: float = 120.0):
    done = threading.Event()
    future = client.call_async(Trigger.Request())
    future.add_done_callback(lambda _: done.set())
    if not done.wait(timeout):
        raise TimeoutError(client.srv_name)
    return future.result()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "load.md")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        (work / "config.yaml").write_text(yaml.safe_dump(CONFIG))
        store = work / "load.sqlite"
        planner = NODES.start(
            "planner node", [sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-p",
                             f"config:={work / 'config.yaml'}", "-p", f"storage:={store}", "-p", "seed:=0", "-p",
                             "auto_propose:=false", "-p", "accept_unsolicited:=true"],
            {**os.environ, "ROS_LOG_DIR": str(work)}, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        rclpy.init()
        node = rclpy.create_node("load_client")
        publisher = node.create_publisher(String, "/gryffin_planner/json/observations", KEEP_ALL)
        recommend = node.create_client(Trigger, "/gryffin_planner/json/recommend")
        status = node.create_client(Trigger, "/gryffin_planner/json/get_status")
        executor = MultiThreadedExecutor(num_threads=2)
        executor.add_node(node)
        threading.Thread(target=executor.spin, daemon=True).start()
        try:
            if not (recommend.wait_for_service(timeout_sec=60) and status.wait_for_service(timeout_sec=60)):
                raise TimeoutError("planner node did not start")
            while publisher.get_subscription_count() == 0:
                time.sleep(0.01)
            batch = observations(1000, "list", rng)
            start = time.perf_counter()
            publisher.publish(String(data=json.dumps(batch)))
            list_seconds = wait_stored(store, 1000)
            singles = observations(1000, "single", rng)
            start = time.perf_counter()
            for item in singles:
                publisher.publish(String(data=json.dumps(item)))
            singles_seconds = wait_stored(store, 2000)
            stored = count(store)

            start = time.perf_counter()
            futures = [recommend.call_async(Trigger.Request()) for _ in range(50)]  # all in flight at once
            deadline = time.monotonic() + 300
            while not all(f.done() for f in futures) and time.monotonic() < deadline:
                time.sleep(0.01)
            concurrent_seconds = time.perf_counter() - start
            ok = [f.result() for f in futures if f.done() and f.result().success]
            ids = [p["experiment_id"] for r in ok for p in json.loads(r.message)["proposals"]]

            busy = threading.Thread(target=lambda: [call(recommend) for _ in range(10)])
            busy.start()
            latencies = []
            while busy.is_alive():
                start = time.perf_counter()
                call(status)
                latencies.append(time.perf_counter() - start)
            busy.join()
        finally:
            executor.shutdown()
            node.destroy_node()
            rclpy.try_shutdown()
            planner.send_signal(signal.SIGINT)
            planner.wait(timeout=30)
    text = (
        "Planner node under load (loopback, this 2-core machine; lab side publishes with KEEP_ALL reliable QoS):\n\n"
        "| measure | result |\n|---|---|\n"
        f"| 1000 observations in one list message -> all stored | {list_seconds:.2f} s |\n"
        f"| 1000 single observation messages in a burst -> all stored | {singles_seconds:.2f} s |\n"
        f"| observations stored / sent | {stored} / 2000 |\n"
        f"| 50 concurrent `~/recommend` calls (n = 2000 observations) | {len(ok)}/50 answered in "
        f"{concurrent_seconds:.1f} s, {len(set(ids))} distinct experiment ids |\n"
        f"| `~/get_status` while the optimizer works ({len(latencies)} calls) | median "
        f"{1000 * statistics.median(latencies):.1f} ms, max {1000 * max(latencies):.1f} ms |\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    with signals_as_interrupt(), NODES:
        main()
