"""`gryffin-ros`: run a closed-loop campaign — flow reactor or redox candidates — with the planner node and an
emulator node over ROS 2 (or the Python API alone with --no-ros), and export a campaign store to CSV/JSON."""

from __future__ import annotations

import argparse
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .campaign import Campaign
from .emulators import FlowReactorEmulator, RedoxEmulator
from .paths import share_path
from .planner import GryffinRosError, Planner
from .planner.config import PlannerConfig, load_config
from .rosenv import ros_environment
from .storage import CampaignStore, StoreError

STALL_SECONDS = 120.0


class Progress:
    """One self-updating terminal line: a bar, experiments done, the best experiment's objectives."""

    def __init__(self, budget: int):
        self.budget, self.start = budget, time.monotonic()
        self.interactive = sys.stdout.isatty()
        self._last = -1

    def show(self, done: int, best: dict[str, float] | None) -> None:
        if done == self._last:
            return
        self._last = done
        filled = int(30 * min(done, self.budget) / self.budget)
        best_text = "-" if best is None else "  ".join(f"{k} {v:.4g}" for k, v in best.items())
        line = (f"[{'#' * filled}{'.' * (30 - filled)}] {done:4d}/{self.budget} experiments  best: {best_text}  "
                f"({time.monotonic() - self.start:.1f} s)")
        print(("\r" + line) if self.interactive else line, end="" if self.interactive else "\n", flush=True)

    def close(self) -> None:
        if self.interactive:
            print(flush=True)


class BestSoFar:
    """Experiments so far and the objectives of the best one (by the campaign's merit, Chimera included); each call
    reads only the observations stored since the last one."""

    def __init__(self, config: PlannerConfig):
        self.planner = Planner(config, seed=0)

    def __call__(self, store: CampaignStore) -> tuple[int, dict[str, float] | None]:
        new = store.observations(skip=len(self.planner.observations))
        if new:
            self.planner.tell(new)
        best = self.planner.best()
        return len(self.planner.observations), None if best is None else best.objectives


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


def plot(store: CampaignStore, config: PlannerConfig, path: Path) -> None:
    """The objectives of the best experiment so far (by the campaign's merit, Chimera included) per experiment."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    judge = Planner(config, seed=0)
    observations, successful, trace = store.observations(), [], []
    for o in observations:
        if not o.failed:
            successful.append(o)
        best = successful[int(np.argmin(judge.merits(successful)))] if successful else None
        trace.append([float("nan") if best is None else best.objectives[obj.name] for obj in config.objectives])
    values = np.array(trace)
    fig, axes = plt.subplots(1, len(config.objectives), figsize=(5 * len(config.objectives), 3.6), squeeze=False)
    for k, (ax, objective) in enumerate(zip(axes[0], config.objectives)):
        ax.plot(range(1, len(values) + 1), values[:, k], drawstyle="steps-post", color="tab:blue")
        ax.set_xlabel("experiment")
        ax.set_ylabel(f"{objective.name} ({objective.goal})")
        ax.grid(alpha=0.3)
    fig.suptitle(f"campaign '{config.name}': the best experiment so far")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run_campaign(config_path: str, config: PlannerConfig, args: argparse.Namespace, out: Path,
                 seed: int | None) -> tuple[int, dict[str, float] | None, bool]:
    """One campaign into `out`: store, CSV, PNG. Returns (experiments, best objectives, interrupted)."""
    out.mkdir(parents=True, exist_ok=True)
    store_path = out / "campaign.sqlite"
    CampaignStore(store_path, config.raw, config.hash).close()  # created (or checked) before anything starts
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
        rows = store.export_csv(out / "experiments.csv")
        if rows:
            plot(store, config, out / "best_so_far.png")
        count, best = BestSoFar(config)(store) if rows else (0, None)
        store.close()
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


def export(args: argparse.Namespace) -> int:
    store = CampaignStore.open_existing(args.store)
    if not args.csv and not args.json:
        raise GryffinRosError("give --csv FILE and/or --json FILE")
    if args.csv:
        print(f"{store.export_csv(args.csv)} observation(s) written to {args.csv}")
    if args.json:
        print(f"{store.export_json(args.json)} observation(s) written to {args.json}")
    store.close()
    return 0


def bench(args: argparse.Namespace) -> int:
    """Run (or resume) the paper's benchmarks and print one summary line per surface and strategy."""
    import json

    from .benchmarks.runner import STRATEGIES, Job, format_summary, run_jobs, summarize
    from .benchmarks.surfaces import SURFACES
    surfaces = [s.strip() for s in args.surface.split(",") if s.strip()]
    strategies = [s.strip() for s in args.strategy.split(",") if s.strip()]
    unknown = [s for s in surfaces if s not in SURFACES] + [s for s in strategies if s not in STRATEGIES]
    if unknown or not surfaces or not strategies:
        print(f"error: unknown surface/strategy {unknown}; surfaces: {', '.join(SURFACES)}; "
              f"strategies: {', '.join(STRATEGIES)}", file=sys.stderr)
        return 2
    groups: dict[tuple[str, str], list[Job]] = {}
    for name in surfaces:
        surface = SURFACES[name]
        budget = args.budget or (100 if surface.kind == "continuous" else 441)
        variant = args.variant if surface.kind == "discrete" else None
        for strategy in strategies:
            jobs = [Job(name, strategy, seed, budget, variant) for seed in range(args.first_seed,
                                                                                 args.first_seed + args.seeds)]
            groups[(name, jobs[0].label)] = jobs
    all_jobs = [job for jobs in groups.values() for job in jobs]

    def progress(job: Job, record: dict) -> None:
        result = (f"optimum at {record['evaluations_to_optimum']}" if record["evaluations_to_optimum"]
                  else f"best {min(record['values'], default=float('nan')):.4g}")
        flag = f"  VIOLATIONS {record['violations']}" if record["violations"] else ""
        flag += f"  ERROR {record['error']}" if record.get("error") else ""
        print(f"{job.surface} {job.label} seed {job.seed}: {result} ({record['seconds']:.1f} s){flag}", flush=True)

    run_jobs(all_jobs, Path(args.out), args.processes, progress)
    summaries = {}
    for (name, label), jobs in groups.items():
        summary = summarize(json.loads(job.path(Path(args.out)).read_text()) for job in jobs)
        summaries[f"{name}/{label}"] = summary
        print(format_summary(name, label, summary))
    if args.json:
        Path(args.json).write_text(json.dumps(summaries, indent=1))
    return 1 if any(s["violations"] for s in summaries.values()) else 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="gryffin-ros", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("campaign", help="run a closed-loop flow-reactor campaign (default: the packaged example)")
    run.add_argument("--config", help="campaign config (YAML/JSON); default: examples/flow_reactor.yaml")
    run.add_argument("--budget", type=int, default=30, help="number of experiments (default 30)")
    run.add_argument("--out", help="output folder (default: a new campaign-<name>-<time> folder here)")
    run.add_argument("--seed", type=int, default=None, help="seed of planner and emulator (default random)")
    run.add_argument("--experiment-time", type=float, default=0.0, help="emulated seconds per experiment")
    run.add_argument("--domain-id", type=int, default=None, help="ROS_DOMAIN_ID (default: from the environment)")
    run.add_argument("--no-ros", action="store_true", help="run planner and emulator in this process, no ROS")
    run.add_argument("--seeds", type=int, default=None,
                     help="run N campaigns (seeds from --seed, default 0) into <out>/seed-<k>/, with a summary")
    run.add_argument("--noise", action="store_true", help="redox emulator: add the published noise to DFT values")
    run.set_defaults(handler=campaign)
    exp = sub.add_parser("export", help="write a campaign store's experiments as CSV and/or JSON")
    exp.add_argument("store", help="campaign SQLite file")
    exp.add_argument("--csv", help="CSV file to write")
    exp.add_argument("--json", help="JSON file to write")
    exp.set_defaults(handler=export)
    ben = sub.add_parser("bench", help="run the paper's benchmark surfaces (parallel over seeds, resumable)")
    ben.add_argument("--surface", required=True, help="surface name(s), comma separated (e.g. branin,slope)")
    ben.add_argument("--strategy", default="adam", help="adam, genetic, gp, auto, random, deap (comma separated)")
    ben.add_argument("--seeds", type=int, default=10, help="number of runs (seeds from --first-seed)")
    ben.add_argument("--first-seed", type=int, default=0)
    ben.add_argument("--budget", type=int, default=None,
                     help="evaluations per run (default 100; discrete: 441, stopping at the optimum)")
    ben.add_argument("--variant", choices=("ordinal", "categorical"), default="ordinal",
                     help="discrete surfaces: ordered options (1-d descriptor) or plain categorical options")
    ben.add_argument("--processes", type=int, default=None, help="parallel runs (default: all cores)")
    ben.add_argument("--out", default="bench-results", help="folder of per-run results (default bench-results)")
    ben.add_argument("--json", help="also write the summaries to this JSON file")
    ben.set_defaults(handler=bench)
    args = parser.parse_args(argv)
    if (getattr(args, "budget", 1) or 1) < 1:
        parser.error("--budget must be at least 1")
    if (getattr(args, "seeds", None) or 1) < 1:
        parser.error("--seeds must be at least 1")
    try:
        return args.handler(args)
    except GryffinRosError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
