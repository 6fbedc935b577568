"""Soak: a long flow-reactor campaign over ROS 2 (planner node + emulator node, typed interfaces, loopback) and the
same campaign through the Python API (`Campaign` in this process), sampled at 100 and every 250 experiments:
resident memory of the planner and emulator processes, ask time, observation -> acknowledgement latency, store size;
at the end the restart-to-ready time of the planner node on the full store, the export time and the best cost found
over time.

    .venv/bin/python -m benchmarks.soak [--budget 5000] [--batch 10] [--every 250] [--out benchmarks/results/soak]

Ask time: from the node's `observation_accepted` event of the batch's last result to its `proposals_ready` event
(both stamped by the node), so it is the ask as the node runs it. Acknowledgement: from this process receiving the
emulator's observation on `~/observations` to it receiving the node's `observation_accepted` for it.
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
from gryffin_ros_msgs.action import Recommend  # noqa: E402
from gryffin_ros_msgs.msg import Event, Observation  # noqa: E402
from gryffin_ros_msgs.srv import GetStatus  # noqa: E402
from rclpy.action import ActionClient  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402

from gryffin_ros.campaign import Campaign  # noqa: E402
from gryffin_ros.cli.progress import BestSoFar  # noqa: E402
from gryffin_ros.emulators import FlowReactorEmulator  # noqa: E402
from gryffin_ros.nodes.qos import EVENTS_QOS, OBSERVATIONS_SUBSCRIPTION_QOS  # noqa: E402
from gryffin_ros.nodes.supervisor import Supervisor, signals_as_interrupt  # noqa: E402

# every node this benchmark starts: stopped when it ends or is stopped (SIGINT, SIGTERM, SIGHUP), and gone by
# itself when this process is killed
NODES = Supervisor(stop_timeout_s=120.0)
from gryffin_ros.planner.config import load_config  # noqa: E402
from gryffin_ros.storage import CampaignStore  # noqa: E402

CONFIG = share_path("examples") / "flow_reactor.yaml"
MILESTONES = (100, 300, 1000, 2000, 5000)
FIRST_SAMPLE = 100  # the latency target is relative to the value at 100 experiments


def following(sample: int, every: int) -> int:
    """The sample after `sample`: 100, then every `every` experiments."""
    return every if sample < every else sample + every


def rss_mb(pid: int | str = "self") -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def store_mb(path: Path) -> float:
    return sum(p.stat().st_size for p in path.parent.glob(path.name + "*") if p.suffix != ".lock") / 2**20


def stamp_s(stamp) -> float:
    return stamp.sec + 1e-9 * stamp.nanosec


def best_cost(store_path: Path, config) -> float | None:
    store = CampaignStore.open_existing(store_path)
    try:
        best = BestSoFar(config)(store)[1]
    finally:
        store.close()
    return None if best is None else best.get("cost")


class Watcher:
    """This process's view of the campaign: observations seen on the wire, the node's events."""

    def __init__(self) -> None:
        self.node = rclpy.create_node("soak_watcher")
        self.lock = threading.Lock()
        self.sent: dict[str, float] = {}
        self.latencies: list[float] = []
        self.ask_times: list[float] = []
        self.accepted = 0
        self._last_accept: float | None = None
        self.node.create_subscription(Observation, "/gryffin_planner/observations", self._on_observation,
                                      OBSERVATIONS_SUBSCRIPTION_QOS)
        self.node.create_subscription(Event, "/gryffin_planner/events", self._on_event, EVENTS_QOS)
        self.status = self.node.create_client(GetStatus, "/gryffin_planner/get_status")
        self.recommend = ActionClient(self.node, Recommend, "/gryffin_planner/recommend")
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        threading.Thread(target=self.executor.spin, daemon=True).start()

    def _on_observation(self, msg: Observation) -> None:
        with self.lock:
            self.sent.setdefault(msg.experiment_id, time.perf_counter())

    def _on_event(self, msg: Event) -> None:
        now = time.perf_counter()
        with self.lock:
            if msg.type == Event.OBSERVATION_ACCEPTED:
                self.accepted += 1
                self._last_accept = stamp_s(msg.stamp)
                if msg.experiment_id in self.sent:
                    self.latencies.append(now - self.sent.pop(msg.experiment_id))
            elif msg.type == Event.PROPOSALS_READY and self._last_accept is not None:
                self.ask_times.append(stamp_s(msg.stamp) - self._last_accept)

    def window(self) -> tuple[list[float], list[float]]:
        with self.lock:
            out = (self.ask_times, self.latencies)
            self.ask_times, self.latencies = [], []
        return out

    def ready_after(self, started: float, count: int, timeout: float = 300.0) -> float:
        """Seconds from `started` until ~/get_status answers with `count` observations."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.status.wait_for_service(timeout_sec=0.5):
                future = self.status.call_async(GetStatus.Request())
                end = time.monotonic() + 2.0
                while not future.done() and time.monotonic() < end:
                    time.sleep(0.01)
                if future.done() and future.result().status.n_observations >= count:
                    return time.perf_counter() - started
                self.status.remove_pending_request(future)
        raise TimeoutError("the restarted planner never answered")

    def single_asks(self, count: int) -> list[float]:
        """Seconds of `count` one-proposal Recommend goals, one after the other (goal sent -> result)."""
        def wait(future):
            deadline = time.monotonic() + 300
            while not future.done():
                if time.monotonic() > deadline:
                    raise TimeoutError("no answer to a Recommend goal")
                time.sleep(0.005)
            return future.result()
        if not self.recommend.wait_for_server(timeout_sec=60):
            raise TimeoutError("no Recommend action server")
        # the experiments still owed after the restart are handed out first, without an ask: take them first
        owed = wait(self.status.call_async(GetStatus.Request())).status.n_pending
        if owed:
            wait(wait(self.recommend.send_goal_async(Recommend.Goal(count=owed))).get_result_async())
        out = []
        for _ in range(count):
            start = time.perf_counter()
            goal = wait(self.recommend.send_goal_async(Recommend.Goal(count=1)))
            wait(goal.get_result_async())
            out.append(time.perf_counter() - start)
        return out

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


def median_ms(values: list[float]) -> str:
    return f"{1000 * statistics.median(values):.0f}" if values else "-"


def over_ros(args: argparse.Namespace, work: Path, config) -> tuple[list[dict], dict]:
    store = work / "soak.sqlite"
    env = {**os.environ, "ROS_LOG_DIR": str(work / "logs")}
    planner_cmd = [sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-p", f"config:={CONFIG}",
                   "-p", f"storage:={store}", "-p", "seed:=0", "-p", f"batch_size:={args.batch}"]
    planner = NODES.start("planner node", planner_cmd, env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    emulator = NODES.start("emulator node", [sys.executable, "-m", "gryffin_ros.nodes.emulator_node", "flow_reactor",
                                             "--ros-args", "-p", "seed:=0", "-p", "objectives:=[X1_X2,cost]"], env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    watcher = Watcher()
    rows, best, started = [], {}, time.perf_counter()
    try:
        next_sample, milestones = min(FIRST_SAMPLE, args.every), list(MILESTONES)
        while next_sample <= args.budget:
            if planner.poll() is not None or emulator.poll() is not None:
                raise RuntimeError("a node exited during the soak")
            with watcher.lock:
                done = watcher.accepted
            if milestones and done >= milestones[0]:
                best[milestones.pop(0)] = best_cost(store, config)
            if done >= next_sample:
                asks, latencies = watcher.window()
                rows.append({"experiments": done, "planner_mb": rss_mb(planner.pid),
                             "emulator_mb": rss_mb(emulator.pid),
                             "ask_ms": median_ms(asks), "ask_max_ms": f"{1000 * max(asks):.0f}" if asks else "-",
                             "ack_ms": median_ms(latencies), "store_mb": store_mb(store),
                             "elapsed_s": time.perf_counter() - started})
                print(rows[-1], flush=True)
                next_sample = following(next_sample, args.every)
            time.sleep(0.2)
        emulator.send_signal(signal.SIGINT)
        emulator.wait(timeout=60)
        planner.send_signal(signal.SIGINT)
        planner.wait(timeout=120)
        restart_started = time.perf_counter()
        planner = NODES.start("planner node", planner_cmd + ["-p", "auto_propose:=false"], env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        restart = watcher.ready_after(restart_started, args.budget)
        single = watcher.single_asks(5)
    finally:
        watcher.close()
        NODES.stop()
    export_started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "gryffin_ros.cli", "export", str(store), "--csv", str(work / "soak.csv")],
                   check=True, capture_output=True)
    export = time.perf_counter() - export_started
    return rows, {"restart_s": restart, "export_s": export, "best_cost": best, "single_ask_s": single}


def in_process(args: argparse.Namespace, work: Path) -> list[dict]:
    emulator = FlowReactorEmulator(seed=0)
    rows, asks, started = [], [], time.perf_counter()
    with Campaign(CONFIG, work / "api.sqlite", seed=0) as campaign:
        next_sample = min(FIRST_SAMPLE, args.every)
        while campaign.n_observations < args.budget:
            t = time.perf_counter()
            proposals = campaign.propose(args.batch)
            asks.append(time.perf_counter() - t)
            for proposal in proposals:
                result = emulator.measure(proposal.params)
                campaign.observe({"experiment_id": proposal.experiment_id, "params": proposal.params,
                                  "objectives": {"X1_X2": result["X1_X2"], "cost": result["cost"]}})
            if campaign.n_observations >= next_sample:
                rows.append({"experiments": campaign.n_observations, "process_mb": rss_mb(), "ask_ms": median_ms(asks),
                             "ask_max_ms": f"{1000 * max(asks):.0f}", "store_mb": store_mb(work / "api.sqlite"),
                             "elapsed_s": time.perf_counter() - started})
                print(rows[-1], flush=True)
                asks, next_sample = [], following(next_sample, args.every)
    return rows


def plot(ros_rows: list[dict], api_rows: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (memory, ask) = plt.subplots(1, 2, figsize=(11, 4))
    x = [r["experiments"] for r in ros_rows]
    memory.plot(x, [r["planner_mb"] for r in ros_rows], label="planner node")
    memory.plot(x, [r["emulator_mb"] for r in ros_rows], label="emulator node")
    if api_rows:
        memory.plot([r["experiments"] for r in api_rows], [r["process_mb"] for r in api_rows], label="Python API")
    memory.set(xlabel="experiments", ylabel="resident memory (MB)", title="memory")
    memory.legend()
    for rows, label in ((ros_rows, "over ROS"), (api_rows, "Python API")):
        points = [(r["experiments"], float(r["ask_ms"])) for r in rows if r["ask_ms"] != "-"]
        if points:
            ask.plot(*zip(*points), label=label)
    ask.set(xlabel="experiments", ylabel="median ask (ms), batch per ask", title="ask time")
    ask.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def table(rows: list[dict], columns: list[tuple[str, str]]) -> str:
    head = "| " + " | ".join(title for _, title in columns) + " |\n|" + "---|" * len(columns) + "\n"
    def cell(value):
        return f"{value:.1f}" if isinstance(value, float) else str(value)
    return head + "".join("| " + " | ".join(cell(r[k]) for k, _ in columns) + " |\n" for r in rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--budget", type=int, default=5000)
    parser.add_argument("--batch", type=int, default=10, help="batch_size of the planner node and the API run")
    parser.add_argument("--every", type=int, default=250)
    parser.add_argument("--no-api", action="store_true", help="skip the Python API run")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "soak")
    args = parser.parse_args()
    config = load_config(CONFIG)
    rclpy.init()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            ros_rows, end = over_ros(args, Path(tmp), config)
            api_rows = [] if args.no_api else in_process(args, Path(tmp))
    finally:
        rclpy.try_shutdown()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    plot(ros_rows, api_rows, args.out.with_suffix(".png"))
    text = (f"Soak: flow-reactor campaign (gryffin_ros/examples/flow_reactor.yaml, seed 0), {args.budget} experiments "
            f"in batches of {args.batch}, 2 cores. Over ROS (planner node + flow_reactor emulator node, typed "
            "interfaces):\n\n"
            + table(ros_rows, [("experiments", "experiments"), ("planner_mb", "planner RSS MB"),
                               ("emulator_mb", "emulator RSS MB"), ("ask_ms", "ask median ms"),
                               ("ask_max_ms", "ask max ms"), ("ack_ms", "obs -> ack median ms"),
                               ("store_mb", "store MB"), ("elapsed_s", "elapsed s")])
            + f"\nRestart of the planner node on the full store, process start to a status answer: "
              f"{end['restart_s']:.1f} s; `gryffin-ros export STORE --csv` (process start included): "
              f"{end['export_s']:.1f} s. Then five one-proposal `Recommend` goals on the {args.budget} "
              f"observations (goal sent -> result): median {statistics.median(end['single_ask_s']):.2f} s, max "
              f"{max(end['single_ask_s']):.2f} s. Best cost (X1 + X2 >= 0.9 first) after "
            + ", ".join(f"{k}: {'-' if v is None else f'{v:.5f}'}" for k, v in end["best_cost"].items()) + ".\n")
    if api_rows:
        text += ("\nThrough the Python API (`Campaign` in one process, same settings):\n\n"
                 + table(api_rows, [("experiments", "experiments"), ("process_mb", "process RSS MB"),
                                    ("ask_ms", "ask median ms"), ("ask_max_ms", "ask max ms"),
                                    ("store_mb", "store MB"), ("elapsed_s", "elapsed s")]))
    args.out.with_suffix(".md").write_text(text)
    args.out.with_suffix(".json").write_text(json.dumps({"ros": ros_rows, "api": api_rows, "end": end}, indent=1))
    print(text)


if __name__ == "__main__":
    with signals_as_interrupt(), NODES:
        main()
