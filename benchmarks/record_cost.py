"""What recording a campaign costs (planner node parameter `record`): the same typed client loop against a planner
node without and with `record`, alternating, on the flow-reactor config with the kde surrogate and Adam (a ~15 ms ask,
so that what the node does per message shows): Recommend round trip, observation -> `observation_accepted` event, and
the planner process's CPU time per experiment (user + system, /proc); then the bag's size.

    python -m benchmarks.record_cost [--calls 40] [--rounds 4] [--out benchmarks/results/record_cost.md]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import rclpy
import yaml
from gryffin_ros_msgs.action import Recommend

from benchmarks.ros_latency import NODES, Lab, stop, wait
from gryffin_ros.nodes.supervisor import signals_as_interrupt
from gryffin_ros.paths import share_path


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def recommend(lab: Lab) -> tuple[str, dict]:
    """One proposal by a Recommend goal under an instrument name, sent again when its acceptance is not back within
    5 s (docs/ros.md, client rules: a busy machine can drop an answer while the client is being matched)."""
    while True:
        future = lab.action.send_goal_async(Recommend.Goal(count=1, instrument="record_cost"))
        try:
            goal = wait(future, 5.0)
        except TimeoutError:
            continue
        proposal = wait(goal.get_result_async()).result.proposals[0]
        return proposal.experiment_id, {v.name: v.number for v in proposal.params}


def run(config: Path, workdir: Path, name: str, calls: int, record: Path | None) -> dict[str, list[float] | float]:
    argv = [sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-r", f"__ns:=/{name}",
            "-p", f"config:={config}", "-p", f"storage:={workdir / (name + '.sqlite')}", "-p", "seed:=0",
            "-p", "auto_propose:=false"] + (["-p", f"record:={record}"] if record else [])
    planner = NODES.start(f"planner node {name}", argv, {**os.environ, "ROS_LOG_DIR": str(workdir)},
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    lab = Lab(name)
    try:
        recommend(lab)  # warm: the first ask builds the planner's caches
        round_trips, to_event = [], []
        cpu_before, wall_before = cpu_seconds(planner.pid), time.perf_counter()
        for i in range(calls):
            start = time.perf_counter()
            experiment_id, params = recommend(lab)
            round_trips.append(time.perf_counter() - start)
            to_event.append(lab.observe(True, experiment_id, params, {"X1_X2": 0.5 + 0.005 * i, "cost": 0.01}))
        cpu = cpu_seconds(planner.pid) - cpu_before
        wall = time.perf_counter() - wall_before
    finally:
        lab.close()
        stop(planner)
    return {"round_trip": round_trips, "to_event": to_event, "cpu_per_experiment": cpu / calls,
            "cpu_share": cpu / wall}


def worst_flush_seconds(workdir: Path) -> tuple[float, int]:
    """The longest a flush takes: the current file just before it is closed for good (SEGMENT_MESSAGES - 1
    messages, a campaign's mix of observations, events and statuses), rewritten whole; and its size in bytes."""
    from gryffin_ros_msgs.msg import CampaignStatus, Event, ObjectiveValue, Observation

    from gryffin_ros.nodes.qos import EVENTS_QOS, LATCHED_QOS, OBSERVATIONS_QOS
    from gryffin_ros.nodes.recorder import SEGMENT_MESSAGES, BagRecorder
    from gryffin_ros.nodes.typed import parameter_values

    recorder = BagRecorder(workdir / "flush_bag", flush_s=3600.0)
    try:
        for i in range(SEGMENT_MESSAGES - 1):
            kind = i % 3
            if kind == 0:
                values = [ObjectiveValue(name="X1_X2", value=0.5), ObjectiveValue(name="cost", value=1.0)]
                msg = Observation(experiment_id=f"{i:036d}", objectives=values,
                                  params=parameter_values({"F_C": 1.0, "F_S": 2.0, "T": 3.0}))
                recorder.record("/gryffin_planner/observations", msg, OBSERVATIONS_QOS)
            elif kind == 1:
                recorder.record("/gryffin_planner/events", Event(type="observation_accepted",
                                                                 experiment_id=f"{i:036d}"), EVENTS_QOS)
            else:
                recorder.record("/gryffin_planner/status", CampaignStatus(campaign="flow", state="idle",
                                                                          n_observations=i), LATCHED_QOS)
        start = time.perf_counter()
        recorder.flush()
        seconds = time.perf_counter() - start
        size = (workdir / "flush_bag" / "flush_bag_0.mcap").stat().st_size
    finally:
        recorder.close()
    return seconds, size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--calls", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=4, help="off/on pairs (off first in even rounds)")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "record_cost.md")
    args = parser.parse_args()
    rclpy.init()
    results: dict[str, list[dict]] = {"off": [], "on": []}
    try:
        with tempfile.TemporaryDirectory() as tmp:
            workdir = Path(tmp)
            raw = yaml.safe_load((share_path("examples") / "flow_reactor.yaml").read_text())
            raw["general"].update({"surrogate": "kde", "acquisition_optimizer": "adam"})
            config = workdir / "flow_light.yaml"
            config.write_text(yaml.safe_dump(raw))
            bags = []
            for k in range(args.rounds):  # off then on, then on then off: a drift of the machine's load cancels
                bags.append(workdir / f"bag{k}")
                for kind in (("off", "on") if k % 2 == 0 else ("on", "off")):
                    results[kind].append(run(config, workdir, f"{kind}{k}", args.calls,
                                             bags[-1] if kind == "on" else None))
            flush_s, flush_bytes = worst_flush_seconds(workdir)
            sizes = [sum(f.stat().st_size for f in bag.iterdir()) for bag in bags]
            messages = [yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"][
                "message_count"] for bag in bags]
    finally:
        rclpy.try_shutdown()

    def pooled(kind: str, key: str) -> list[float]:
        return [v for r in results[kind] for v in r[key]]

    def ms(values: list[float]) -> str:
        ordered = sorted(values)
        return (f"{1000 * statistics.median(values):.1f} ms (p90 {1000 * ordered[int(0.9 * (len(ordered) - 1))]:.1f},"
                f" max {1000 * max(values):.1f})")

    def cpu(kind: str) -> str:
        per = [1000 * r["cpu_per_experiment"] for r in results[kind]]
        share = [100 * r["cpu_share"] for r in results[kind]]
        return f"{statistics.mean(per):.1f} ms ({', '.join(f'{v:.1f}' for v in per)}); {statistics.mean(share):.0f}%"

    n = args.calls * args.rounds
    text = (f"Planner node over ROS 2 (Fast DDS, loopback), typed client, flow-reactor config with `surrogate: kde` "
            f"and Adam, {args.rounds} rounds of an off and an on run (alternating which goes first), {args.calls} "
            f"experiments each ({n} per column), "
            f"2 cores; median (p90, max):\n\n"
            f"| measure | `record` off | `record` on |\n|---|---|---|\n"
            f"| Recommend round trip, one proposal | {ms(pooled('off', 'round_trip'))} | "
            f"{ms(pooled('on', 'round_trip'))} |\n"
            f"| observation published -> `observation_accepted` event received | {ms(pooled('off', 'to_event'))} | "
            f"{ms(pooled('on', 'to_event'))} |\n"
            f"| planner process CPU per experiment (mean of rounds; each round); CPU share while the loop ran | "
            f"{cpu('off')} | {cpu('on')} |\n"
            f"| bag size after {args.calls} experiments (+1 warm-up) | - | "
            f"{statistics.mean(sizes) / 1024:.0f} KiB, {statistics.mean(messages):.0f} messages |\n"
            f"| the longest flush: the current MCAP file rewritten whole just before it is closed (1999 messages, "
            f"{flush_bytes / 1024:.0f} KiB), at most once a second, in the recorder's thread | - | "
            f"{1000 * flush_s:.0f} ms |\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    with signals_as_interrupt(), NODES:
        main()
