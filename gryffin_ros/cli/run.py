"""`gryffin-ros campaign`: a closed-loop campaign against an emulator — the planner node and the emulator node as
separate processes over ROS 2 on loopback, or (--no-ros) a `Campaign` and the emulator in this process — into one
output folder (store, CSV, plot)."""

from __future__ import annotations

import argparse
import signal
import subprocess
import sys
import time
from pathlib import Path

from ..campaign import Campaign
from ..emulators import FlowReactorEmulator, RedoxEmulator
from ..paths import share_path
from ..planner import GryffinRosError
from ..planner.config import PlannerConfig, load_config
from ..rosenv import ros_environment
from ..storage import CampaignStore, StoreError
from .outputs import plot
from .progress import BestSoFar, Progress

STALL_SECONDS = 120.0


def emulator_settings(config: PlannerConfig) -> tuple[str, list[str], list[str]]:
    """Which emulator fits the config ('flow_reactor' or 'redox'), its parameter names and the reported objectives."""
    names = [p.name for p in config.space.parameters]
    objectives = [o.name for o in config.objectives]
    if set(names) == set(RedoxEmulator.parameters):
        kind, outputs = "redox", RedoxEmulator.outputs
    elif len(names) == 3 and all(p.kind == "continuous" for p in config.space.parameters):
        kind, outputs = "flow_reactor", FlowReactorEmulator.outputs
    else:
        raise GryffinRosError("no emulator fits this config: the flow reactor needs three continuous parameters (C60 "
                              f"flow, sultine flow, temperature), the redox lookup the parameters "
                              f"{list(RedoxEmulator.parameters)}")
    unknown = [o for o in objectives if o not in outputs]
    if unknown:
        raise GryffinRosError(f"the {kind} emulator reports {list(outputs)}; objective(s) {unknown} unknown")
    return kind, names, objectives


def run_local(config_path: str, config: PlannerConfig, store_path: Path, args: argparse.Namespace,
              progress: Progress, seed: int | None) -> None:
    """The same campaign through the Python API: a Campaign and the emulator in this process, same store."""
    kind, names, objectives = emulator_settings(config)
    emulator = (RedoxEmulator(noise=args.noise, seed=seed) if kind == "redox"
                else FlowReactorEmulator(seed=seed, parameters=tuple(names)))
    with Campaign(config_path, store_path, seed=seed) as campaign:
        while campaign.n_observations < args.budget:
            for proposal in campaign.pending or campaign.propose():
                result = emulator.measure(proposal.params)
                campaign.observe({"experiment_id": proposal.experiment_id, "params": proposal.params,
                                  "objectives": {k: result[k] for k in objectives}, "meta": result})
                best = campaign.best
                progress.show(campaign.n_observations, best.objectives if best else None)


def stop(processes: list[subprocess.Popen], env: dict[str, str]) -> None:
    """SIGINT (clean rclpy shutdown), then SIGTERM, then SIGKILL; then Fast DDS shared memory left by dead
    participants is removed (a node interrupted mid-callback sometimes leaves some even when it exits cleanly)."""
    for process in processes:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
    for process in processes:
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.terminate()
            try:
                process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
    fastdds = Path(sys.executable).with_name("fastdds")
    if fastdds.exists():
        subprocess.run([str(fastdds), "shm", "clean"], env=env, capture_output=True, timeout=30)


def run_ros(config_path: str, config: PlannerConfig, store_path: Path, args: argparse.Namespace,
            progress: Progress, out: Path, seed: int | None) -> None:
    """Planner node and emulator node as separate processes over DDS on loopback; progress read from the store
    (read-only: the planner node holds it)."""
    kind, names, objectives = emulator_settings(config)
    env = ros_environment(domain_id=args.domain_id)
    env["ROS_LOG_DIR"] = str(out / "ros_logs")
    seed = -1 if seed is None else seed
    planner_cmd = [sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args",
                   "-p", f"config:={config_path}", "-p", f"storage:={store_path}", "-p", f"seed:={seed}"]
    emulator_cmd = [sys.executable, "-m", "gryffin_ros.nodes.emulator_node", kind, "--ros-args",
                    "-p", f"seed:={seed}", "-p", f"experiment_time_s:={args.experiment_time}",
                    "-p", f"objectives:=[{','.join(objectives)}]"]
    emulator_cmd += (["-p", f"noise:={str(args.noise).lower()}"] if kind == "redox"
                     else ["-p", f"parameters:=[{','.join(names)}]"])
    logs = [open(out / "planner_node.log", "w"), open(out / f"{kind}_node.log", "w")]
    processes = [subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT)
                 for cmd, log in zip((planner_cmd, emulator_cmd), logs)]
    best_value = BestSoFar(config)
    store = None
    try:
        done, last_change = -1, time.monotonic()
        while True:
            if store is None and store_path.is_file():
                try:
                    store = CampaignStore.open_existing(store_path)
                except StoreError:  # the node is still creating it
                    store = None
            count, best = best_value(store) if store is not None else (0, None)
            progress.show(count, best)
            if count >= args.budget:
                return
            if count != done:
                done, last_change = count, time.monotonic()
            for process, log in zip(processes, logs):
                if process.poll() is not None:
                    raise GryffinRosError(f"{Path(log.name).stem} exited with code {process.returncode}; see "
                                          f"{log.name}")
            if time.monotonic() - last_change > STALL_SECONDS:
                raise GryffinRosError(f"no new observation for {STALL_SECONDS:.0f} s; see the logs in {out}")
            time.sleep(0.1)
    finally:
        stop(processes, env)
        for log in logs:
            log.close()
        if store is not None:
            store.close()


def run_campaign(config_path: str, config: PlannerConfig, args: argparse.Namespace, out: Path,
                 seed: int | None) -> tuple[int, dict[str, float] | None, bool]:
    """One campaign into `out`: store, CSV, PNG. Returns (experiments, best objectives, interrupted)."""
    out.mkdir(parents=True, exist_ok=True)
    store_path = out / "campaign.sqlite"
    CampaignStore(store_path, config.raw, config.hash).close()  # created (or checked) before anything starts
    board = None
    if args.dashboard is not None:  # the live page, read from the store (whichever process writes it)
        from ..dashboard import start
        board = start(store_path, "127.0.0.1", args.dashboard, Path(config_path).parent)
        print(f"dashboard: {board.url}", flush=True)
    progress = Progress(args.budget)
    interrupted = False
    try:
        if args.no_ros:
            run_local(config_path, config, store_path, args, progress, seed)
        else:
            run_ros(config_path, config, store_path, args, progress, out, seed)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        progress.close()
        store = CampaignStore.open_existing(store_path)
        try:
            rows = store.export_csv(out / "experiments.csv")
            if rows:
                plot(store, config, out / "best_so_far.png")
            count, best = BestSoFar(config)(store) if rows else (0, None)
        finally:
            store.close()
            if board is not None:
                board.close()
    print(f"{rows} experiment(s): {out / 'experiments.csv'}, {out / 'best_so_far.png'}, {out / 'campaign.sqlite'}")
    return count, best, interrupted


def campaign(args: argparse.Namespace) -> int:
    config_path = str(Path(args.config).resolve()) if args.config else str(share_path("examples") / "flow_reactor.yaml")
    config = load_config(config_path)
    emulator_settings(config)  # fail before starting anything when no emulator fits
    out = Path(args.out) if args.out else Path.cwd() / f"campaign-{config.name}-{time.strftime('%Y%m%d-%H%M%S')}"
    transport = "Python API" if args.no_ros else "planner node + emulator node over ROS 2"
    print(f"campaign '{config.name}' ({config_path}), budget {args.budget}, {transport}; output {out}")
    if args.seeds is None:
        return 130 if run_campaign(config_path, config, args, out, args.seed)[2] else 0
    first = args.seed or 0
    rows = ["| seed | experiments | best |", "|---|---|---|"]
    for seed in range(first, first + args.seeds):
        print(f"seed {seed}:")
        count, best, interrupted = run_campaign(config_path, config, args, out / f"seed-{seed}", seed)
        shown = "-" if best is None else ", ".join(f"{k} {v:.4g}" for k, v in best.items())
        rows.append(f"| {seed} | {count} | {shown} |")
        if interrupted:
            break
    (out / "summary.md").write_text(f"campaign '{config.name}', budget {args.budget}\n\n" + "\n".join(rows) + "\n")
    print("\n".join(rows))
    return 130 if interrupted else 0
