"""Latency of the planner node over ROS 2 on loopback, typed interfaces and JSON bridge side by side (one planner
node each, same config): recommend round trip, observation -> event; how long a cancel of a long Recommend goal
takes to end it; the wall time of a 30-experiment closed-loop flow-reactor campaign (emulator experiment time 0).

    python -m benchmarks.ros_latency [--calls 20] [--out benchmarks/results/ros_latency.md]
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

from gryffin_ros.nodes.rosenv import ros_environment
from gryffin_ros.paths import share_path

os.environ.update(ros_environment())

import rclpy  # noqa: E402
import yaml  # noqa: E402
from gryffin_ros_msgs.action import Recommend  # noqa: E402
from gryffin_ros_msgs.msg import Event, ObjectiveValue, Observation  # noqa: E402
from rclpy.action import ActionClient  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from gryffin_ros.nodes.qos import EVENTS_QOS, OBSERVATIONS_QOS  # noqa: E402
from gryffin_ros.nodes.supervisor import Supervisor, signals_as_interrupt  # noqa: E402

# every node this benchmark starts: stopped when it ends or is stopped (SIGINT, SIGTERM, SIGHUP), and gone by
# itself when this process is killed
NODES = Supervisor(stop_timeout_s=120.0)
from gryffin_ros.nodes.typed import parameter_values  # noqa: E402

# the long recommendation that is canceled: the genetic optimizer over six continuous parameters, 400 points
LONG_CONFIG = {"name": "long", "parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0}
                                              for i in range(6)],
               "objectives": [{"name": "y", "goal": "min"}], "constraints": ["x0 + x1 < 1.5"],
               "general": {"acquisition_optimizer": "genetic", "surrogate": "kde"}}


def wait(future, timeout: float = 120.0):
    done = threading.Event()
    future.add_done_callback(lambda _: done.set())
    if not done.wait(timeout):
        raise TimeoutError("no answer")
    return future.result()


def start_planner(config: Path, workdir: Path, name: str) -> subprocess.Popen:
    return NODES.start(f"planner node {name}", [
        sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-r", f"__ns:=/{name}", "-p",
        f"config:={config}", "-p", f"storage:={workdir / (name + '.sqlite')}", "-p", "seed:=0", "-p",
        "auto_propose:=false"], {**os.environ, "ROS_LOG_DIR": str(workdir)}, stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL)


class Lab:
    """One client of both interfaces; `typed` chooses which one a measurement uses."""

    def __init__(self, ns: str) -> None:
        self.node = rclpy.create_node(f"bench_client_{ns}")
        base = f"/{ns}/gryffin_planner"
        self.events: dict[str, float] = {}
        self.arrived = threading.Event()
        self.node.create_subscription(Event, f"{base}/events", lambda m: self._event(m.experiment_id), EVENTS_QOS)
        self.node.create_subscription(String, f"{base}/json/events",
                                      lambda m: self._event(json.loads(m.data).get("experiment_id", "")), EVENTS_QOS)
        self.typed_pub = self.node.create_publisher(Observation, f"{base}/observations", OBSERVATIONS_QOS)
        self.json_pub = self.node.create_publisher(String, f"{base}/json/observations", OBSERVATIONS_QOS)
        self.action = ActionClient(self.node, Recommend, f"{base}/recommend")
        self.trigger = self.node.create_client(Trigger, f"{base}/json/recommend")
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        threading.Thread(target=self.executor.spin, daemon=True).start()
        if not (self.action.wait_for_server(timeout_sec=120) and self.trigger.wait_for_service(timeout_sec=120)):
            raise TimeoutError("planner node did not start")
        while self.typed_pub.get_subscription_count() == 0 or self.json_pub.get_subscription_count() == 0:
            time.sleep(0.01)

    def _event(self, experiment_id: str) -> None:
        self.events.setdefault(experiment_id, time.perf_counter())
        self.arrived.set()

    def recommend(self, typed: bool) -> tuple[str, dict]:
        if typed:
            goal = wait(self.action.send_goal_async(Recommend.Goal(count=1)))
            proposal = wait(goal.get_result_async()).result.proposals[0]
            return proposal.experiment_id, {p.name: p.number for p in proposal.params}
        proposal = json.loads(wait(self.trigger.call_async(Trigger.Request())).message)["proposals"][0]
        return proposal["experiment_id"], proposal["params"]

    def observe(self, typed: bool, experiment_id: str, params: dict, objectives: dict) -> float:
        sent = time.perf_counter()
        if typed:
            values = [ObjectiveValue(name=k, value=v) for k, v in objectives.items()]
            self.typed_pub.publish(Observation(experiment_id=experiment_id, params=parameter_values(params),
                                               objectives=values))
        else:
            self.json_pub.publish(String(data=json.dumps({"experiment_id": experiment_id, "params": params,
                                                          "objectives": objectives})))
        while experiment_id not in self.events:
            self.arrived.wait(timeout=1.0)
            self.arrived.clear()
        return self.events[experiment_id] - sent

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


def stop(process: subprocess.Popen) -> None:
    process.send_signal(signal.SIGINT)
    process.wait(timeout=60)


def node_latencies(calls: int, workdir: Path, general: dict | None = None
                   ) -> dict[str, tuple[list[float], list[float]]]:
    """Per interface: recommend round trips and observation -> event latencies, on the flow-reactor config (as it
    is, or with these `general` settings)."""
    config = share_path("examples") / "flow_reactor.yaml"
    if general:
        raw = yaml.safe_load(config.read_text())
        raw["general"].update(general)
        config = workdir / "flow_fast.yaml"
        config.write_text(yaml.safe_dump(raw))
    results = {}
    for typed in (True, False):
        name = ("typed" if typed else "json") + ("_fast" if general else "")
        planner = start_planner(config, workdir, name)
        lab = Lab(name)
        try:
            round_trips, to_event = [], []
            for i in range(calls):
                start = time.perf_counter()
                experiment_id, params = lab.recommend(typed)
                round_trips.append(time.perf_counter() - start)
                to_event.append(lab.observe(typed, experiment_id, params, {"X1_X2": 0.5 + 0.01 * i, "cost": 0.01}))
            results["typed" if typed else "json"] = (round_trips, to_event)
        finally:
            lab.close()
            stop(planner)
    return results


def cancel_latencies(repeats: int, workdir: Path) -> list[float]:
    """Seconds from sending the cancel of a running 400-point Recommend goal to its canceled result."""
    config = workdir / "long.yaml"
    config.write_text(yaml.safe_dump(LONG_CONFIG))
    planner = start_planner(config, workdir, "long")
    lab = Lab("long")
    try:
        for i in range(2):  # a model from here on
            experiment_id, params = lab.recommend(True)
            lab.observe(True, experiment_id, params, {"y": float(i)})
        out = []
        for _ in range(repeats):
            optimizing = threading.Event()
            goal = wait(lab.action.send_goal_async(
                Recommend.Goal(count=400), feedback_callback=lambda f, seen=optimizing: (
                    seen.set() if f.feedback.stage in ("optimizing", "selecting") else None)))
            optimizing.wait(120)
            start = time.perf_counter()
            wait(goal.cancel_goal_async())
            result = wait(goal.get_result_async())
            out.append(time.perf_counter() - start)
            if result.status != 5:
                raise RuntimeError(f"goal ended with status {result.status}, not canceled")
        return out
    finally:
        lab.close()
        stop(planner)


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
    rclpy.init()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            workdir = Path(tmp)
            latencies = node_latencies(args.calls, workdir)
            # a ~15 ms ask (kde surrogate, Adam): what the interface itself costs shows
            light = node_latencies(args.calls, workdir, {"surrogate": "kde", "acquisition_optimizer": "adam"})
            cancels = cancel_latencies(5, workdir)
            loop = closed_loop_seconds(workdir)
    finally:
        rclpy.try_shutdown()

    def ms(values: list[float]) -> str:
        return f"{1000 * statistics.median(values):.1f} ms (max {1000 * max(values):.1f} ms)"
    typed, bridge = latencies["typed"], latencies["json"]
    text = (f"Planner node over ROS 2 (Fast DDS, loopback), {args.calls} calls per interface, flow-reactor config, "
            f"2 cores; median (max):\n\n"
            f"| measure | typed (gryffin_ros_msgs) | JSON bridge (`~/json/...`) |\n|---|---|---|\n"
            f"| recommend round trip, one proposal (includes one ask: the example's settings, portfolio surrogate "
            f"(the GP here) and Genetic, ~0.4 s in-process): `Recommend` goal to result vs `~/json/recommend` | "
            f"{ms(typed[0])} | {ms(bridge[0])} |\n"
            f"| the same with `surrogate: kde` and Adam (~15 ms in-process: the interface shows) | "
            f"{ms(light['typed'][0])} | {ms(light['json'][0])} |\n"
            f"| observation published -> `observation_accepted` event received | {ms(typed[1])} | "
            f"{ms(bridge[1])} |\n"
            f"| the same, kde and Adam | {ms(light['typed'][1])} | {ms(light['json'][1])} |\n\n"
            f"| measure | result |\n|---|---|\n"
            f"| cancel of a running 400-point `Recommend` goal -> canceled result (5 goals) | {ms(cancels)} |\n"
            f"| 30-experiment closed loop, `gryffin-ros campaign --budget 30` (both nodes started) | {loop:.1f} s |\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    with signals_as_interrupt(), NODES:
        main()
