"""The problem portfolio side by side (issue #20): our planner's surrogates and the GP peers (BoTorch, GPyOpt) on the
families of `portfolio_tasks.py`, through the peer harness (`../shared/peers`: the same initial points per seed, one
thread per run, ask time as process CPU), in one command and one table.

    .venv/bin/python -m benchmarks.portfolio [--seeds 0-5] [--ours default,kde,gp] [--peers botorch,gpyopt]
                                             [--tasks NAMES] [--out portfolio-results] [--lanes 2]

Runs are stored by the harness under --out (one JSON per peer, task and seed) and skipped when present, so an
interrupted run resumes and `--aggregate` alone rebuilds the table. Peers' virtual environments come from
`../shared/peers/install_peer.sh botorch` / `gpyopt` (in $PEERVENVS, default /tmp/peervenvs).

Score of a run: normalized regret (best - reference) / (best of the common initial design - reference), 1 = no
progress past the initial points, 0 = the reference (the closed-form optimum, or a dense grid search refined by a
coordinate search, or the best value any run found if that is lower). A family's score is the mean of its tasks'
mean regrets; its s.e. is sqrt(sum of the tasks' squared s.e.) / number of tasks (tasks are independent runs; a peer
may have fewer seeds on some tasks: the table says how many).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PEERS_DIR = Path(os.environ.get("PEERS_DIR", ROOT.parent / "shared" / "peers"))
VENVS = Path(os.environ.get("PEERVENVS", "/tmp/peervenvs"))
sys.path.insert(0, str(PEERS_DIR))  # the harness's `problems`, which the task modules build on

from benchmarks import portfolio_tasks  # noqa: E402

OURS = {"default": "gryffin_ros_default", "kde": "gryffin_ros_kde", "gp": "gryffin_ros_gp",
        "auto": "gryffin_ros_auto"}


def seeds_of(spec: str) -> list[int]:
    out: list[int] = []
    for part in spec.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def job(peer: str, python: str, tasks: list[str], seeds: list[int], out: Path, module: str = "portfolio_tasks"
        ) -> str:
    """One harness process: `peer` on `tasks` (of the task module `module`) x `seeds`, skipping runs already
    stored."""
    todo = [(t, s) for t in tasks for s in seeds if not (out / t / f"{peer}_seed{s}.json").exists()]
    if not todo:
        return f"{peer}: nothing to do"
    env = dict(os.environ, OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               PEER_PATH=os.pathsep.join([str(ROOT / "benchmarks" / "peers"), str(ROOT / "benchmarks"), str(ROOT)]))
    done = []
    for task in sorted({t for t, _ in todo}):
        task_seeds = ":".join(str(s) for t, s in todo if t == task)
        result = subprocess.run([python, str(PEERS_DIR / "harness.py"), "--peer", peer, "--task-module",
                                 module, "--tasks", task, "--seeds", f"{task}={task_seeds}", "--out",
                                 str(out)], cwd=PEERS_DIR, env=env, capture_output=True, text=True)
        if result.returncode:
            raise RuntimeError(f"{peer} on {task} failed:\n{result.stderr[-3000:]}")
        done.append(task)
    return f"{peer}: {', '.join(done)}"


def load(out: Path, tasks: list[str], seeds: list[int], peers: list[str]) -> dict:
    runs: dict[tuple[str, str], list[dict]] = {}
    for task in tasks:
        for peer in peers:
            for seed in seeds:
                path = out / task / f"{peer}_seed{seed}.json"
                if path.exists():
                    runs.setdefault((task, peer), []).append(json.loads(path.read_text()))
    return runs


def mean_se(values: list[float]) -> tuple[float, float]:
    m = statistics.fmean(values)
    return m, (statistics.stdev(values) / math.sqrt(len(values)) if len(values) > 1 else float("nan"))


def aggregate(out: Path, tasks: list[str], seeds: list[int], peers: list[str]) -> dict:
    runs = load(out, tasks, seeds, peers)
    result: dict = {"tasks": {}, "families": {}, "peers": peers, "seeds": seeds}
    regrets: dict[tuple[str, str], dict[int, float]] = {}
    for task_name in tasks:
        task = portfolio_tasks.TASKS[task_name]()
        found = [r["best"] for p in peers for r in runs.get((task_name, p), []) if r["best"] is not None]
        reference = min([task.reference()] + found)
        entry = {"family": task.family, "reference": reference, "budget": task.budget, "peers": {}}
        for peer in peers:
            rows = runs.get((task_name, peer), [])
            if not rows:
                continue
            per_seed = {}
            for r in rows:
                initial = min(task.objective(x) for x in task.initial_points(r["seed"]))
                per_seed[r["seed"]] = (r["best"] - reference) / (initial - reference)
            regrets[(task_name, peer)] = per_seed
            m, se = mean_se(list(per_seed.values()))
            entry["peers"][peer] = {
                "regret": m, "se": se, "seeds": len(rows), "violations": sum(r["violations"] for r in rows),
                "asks": sum(r["n_asks"] for r in rows), "errors": sum(bool(r["error"]) for r in rows),
                "ask_cpu_median_s": statistics.median(r["ask_cpu_median_s"] for r in rows
                                                      if r["ask_cpu_median_s"] is not None),
                "chose": {k: sum(r.get("peer_info", {}).get(k, 0) for r in rows)
                          for k in sorted({k for r in rows for k in r.get("peer_info", {})})}}
        result["tasks"][task_name] = entry
    for family in portfolio_tasks.FAMILIES:
        members = [t for t in tasks if result["tasks"][t]["family"] == family]
        if not members:
            continue
        fam = {}
        for peer in peers:
            if not all((t, peer) in regrets for t in members):
                continue
            tasks_of = [result["tasks"][t]["peers"][peer] for t in members]
            m = statistics.fmean(v["regret"] for v in tasks_of)
            se = math.sqrt(sum(v["se"] ** 2 for v in tasks_of)) / len(tasks_of)
            fam[peer] = {"regret": m, "se": se, "seeds": sorted({v["seeds"] for v in tasks_of}),
                         "ask_cpu_median_s": statistics.median(
                result["tasks"][t]["peers"][peer]["ask_cpu_median_s"] for t in members)}
        result["families"][family] = {"tasks": members, "peers": fam}
    return result


def fmt(m: float, se: float) -> str:
    return f"{m:.3f}" if math.isnan(se) else f"{m:.3f} ± {se:.3f}"  # one seed: no s.e.


def table(result: dict) -> str:
    peers = [p for p in result["peers"] if any(p in f["peers"] for f in result["families"].values())]
    lines = ["| family (tasks) | " + " | ".join(peers) + " |", "|---" * (len(peers) + 1) + "|"]
    for family, f in result["families"].items():
        best = min(v["regret"] for v in f["peers"].values())
        cells = []
        for p in peers:
            v = f["peers"].get(p)
            seeds = "" if v is None or v["seeds"] == [len(result["seeds"])] else \
                f" ({'/'.join(map(str, v['seeds']))} seed{'s' if max(v['seeds']) > 1 else ''})"
            cells.append("—" if v is None else (f"**{fmt(v['regret'], v['se'])}**{seeds}" if v["regret"] == best
                                                 else fmt(v["regret"], v["se"]) + seeds))
        lines.append(f"| {family} ({', '.join(f['tasks'])}) | " + " | ".join(cells) + " |")
    lines.append("| median CPU per ask (s), per family: " + "; ".join(result["families"]) + " | " + " | ".join(
        " / ".join(f"{f['peers'][p]['ask_cpu_median_s']:.2f}" if p in f["peers"] else "—"
                   for f in result["families"].values()) for p in peers) + " |")
    lines += ["", "Per task (normalized regret, mean ± s.e. over seeds; violations / asks):", "",
              "| task | budget | reference | " + " | ".join(peers) + " |", "|---" * (len(peers) + 3) + "|"]
    for name, t in result["tasks"].items():
        cells = []
        for p in peers:
            v = t["peers"].get(p)
            cells.append("—" if v is None else f"{fmt(v['regret'], v['se'])} ({v['violations']}/{v['asks']})")
        lines.append(f"| {name} | {t['budget']} | {t['reference']:.5g} | " + " | ".join(cells) + " |")
    choices = [f"{p} on {name}: {t['peers'][p]['chose']}" for name, t in result["tasks"].items() for p in peers
               if p in t["peers"] and t["peers"][p]["chose"]]
    if choices:
        lines += ["", "Surrogates chosen (proposals, summed over seeds):", ""] + [f"- {c}" for c in choices]
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", default="0-5")
    ap.add_argument("--tasks", default=",".join(portfolio_tasks.TASKS))
    ap.add_argument("--ours", default="default,kde,gp", help=f"our settings, of {list(OURS)}")
    ap.add_argument("--peers", default="botorch,gpyopt")
    ap.add_argument("--out", default="portfolio-results")
    ap.add_argument("--lanes", type=int, default=2, help="harness processes at once (one thread each)")
    ap.add_argument("--aggregate", action="store_true", help="only rebuild the table from stored runs")
    a = ap.parse_args()
    out = Path(a.out).resolve()
    tasks, seeds = a.tasks.split(","), seeds_of(a.seeds)
    ours = [OURS[o] for o in filter(None, a.ours.split(","))]
    peers = list(filter(None, a.peers.split(",")))
    if not a.aggregate:
        jobs = [(p, sys.executable) for p in ours] + [(p, str(VENVS / p / "bin" / "python")) for p in peers]
        with ThreadPoolExecutor(a.lanes) as pool:
            for message in pool.map(lambda j: job(j[0], j[1], tasks, seeds, out), jobs):
                print(message, flush=True)
    result = aggregate(out, tasks, seeds, ours + peers)
    (out / "portfolio.json").write_text(json.dumps(result, indent=1))
    text = table(result)
    (out / "portfolio.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
