"""`gryffin-ros campaign`: a closed-loop campaign against an emulator — the planner node and the emulator node as
separate processes over ROS 2 on loopback, or (--no-ros) a `Campaign` and the emulator in this process — into one
output folder (store, CSV, plot)."""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

from ..campaign import Campaign
from ..emulators import FlowReactorEmulator, RedoxEmulator
from ..nodes.rosenv import ros_environment
from ..nodes.supervisor import Interrupted, Supervisor, signals_as_interrupt
from ..paths import share_path
from ..planner import GryffinRosError
from ..planner.config import PlannerConfig, load_config
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


def clean_shared_memory(env: dict[str, str]) -> None:
    """Remove Fast DDS shared memory left by dead participants (a node interrupted mid-callback sometimes leaves
    some even when it exits cleanly)."""
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
    if args.record:  # a bag is never overwritten: a continued campaign records into the next free name
        bag = next(out / name for name in ("bag", *(f"bag_{k}" for k in range(1, 10**6)))
                   if not (out / name).exists())
        planner_cmd += ["-p", f"record:={bag}"]
        print(f"recording: {bag}", flush=True)
    emulator_cmd = [sys.executable, "-m", "gryffin_ros.nodes.emulator_node", kind, "--ros-args",
                    "-p", f"seed:={seed}", "-p", f"experiment_time_s:={args.experiment_time}",
                    "-p", f"objectives:=[{','.join(objectives)}]"]
    emulator_cmd += (["-p", f"noise:={str(args.noise).lower()}"] if kind == "redox"
                     else ["-p", f"parameters:=[{','.join(names)}]"])
    logs = {"planner node": open(out / "planner_node.log", "a"),
            f"{kind} emulator node": open(out / f"{kind}_node.log", "a")}
    supervisor = Supervisor()
    best_value = BestSoFar(config)
    store = None
    try:
        processes = [supervisor.start(name, cmd, env, stdout=log, stderr=subprocess.STDOUT)
                     for (name, log), cmd in zip(logs.items(), (planner_cmd, emulator_cmd))]
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
            for process, (name, log) in zip(processes, logs.items()):
                if process.poll() is not None:
                    raise GryffinRosError(f"the {name} exited with code {process.returncode}; see {log.name}")
            if time.monotonic() - last_change > STALL_SECONDS:
                raise GryffinRosError(f"no new observation for {STALL_SECONDS:.0f} s; see the logs in {out}")
            time.sleep(0.1)
    finally:
        if store is not None:
            store.close()
        ended = supervisor.stop()
        for log in logs.values():
            log.close()
        clean_shared_memory(env)
        for end in ended:  # an operator sees how each node ended; one that had to be forced is named
            print(f"{end}" + ("" if end.clean else f"; see {logs[end.name].name}"), file=sys.stderr, flush=True)


def run_campaign(config_path: str, config: PlannerConfig, args: argparse.Namespace, out: Path,
                 seed: int | None) -> tuple[int, dict[str, float] | None, int]:
    """One campaign into `out`: store, CSV, PNG. Returns (experiments, best objectives, 0 or the exit code of the
    signal that stopped it: 130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP)."""
    out.mkdir(parents=True, exist_ok=True)
    store_path = out / "campaign.sqlite"
    CampaignStore(store_path, config.raw, config.hash).close()  # created (or checked) before anything starts
    board = None
    if args.dashboard is not None:  # the live page, read from the store (whichever process writes it)
        from ..dashboard import start
        board = start(store_path, "127.0.0.1", args.dashboard, Path(config_path).parent)
        print(f"dashboard: {board.url}", flush=True)
    progress = Progress(args.budget)
    interrupted = 0
    try:
        if args.no_ros:
            run_local(config_path, config, store_path, args, progress, seed)
        else:
            run_ros(config_path, config, store_path, args, progress, out, seed)
    except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM or SIGHUP (signals_as_interrupt)
        interrupted = exc.exit_code if isinstance(exc, Interrupted) else 130
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
    if args.record and args.no_ros:
        raise GryffinRosError("--record records the planner node's messages: it needs the nodes (leave out --no-ros)")
    config_path = str(Path(args.config).resolve()) if args.config else str(share_path("examples") / "flow_reactor.yaml")
    config = load_config(config_path)
    emulator_settings(config)  # fail before starting anything when no emulator fits
    out = Path(args.out) if args.out else Path.cwd() / f"campaign-{config.name}-{time.strftime('%Y%m%d-%H%M%S')}"
    transport = "Python API" if args.no_ros else "planner node + emulator node over ROS 2"
    print(f"campaign '{config.name}' ({config_path}), budget {args.budget}, {transport}; output {out}")
    with signals_as_interrupt():
        return run_campaigns(config_path, config, args, out)


def run_campaigns(config_path: str, config: PlannerConfig, args: argparse.Namespace, out: Path) -> int:
    if args.seeds is None:
        return run_campaign(config_path, config, args, out, args.seed)[2]
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
    return interrupted
