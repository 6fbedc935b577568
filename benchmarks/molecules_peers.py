"""Molecules side by side (#35 item 4): our planner with RDKit descriptors of SMILES options, the same options without
descriptors, BayBE with its chemical encodings of the same SMILES and with one-hot options, and random choice, on the
57 BTZ molecules (`molecule_tasks.py`; data origin and license in `benchmarks/data/README.md`), through the peer
harness (../shared/peers: the same 5 random initial molecules per seed, 40 experiments, ask time as process CPU on one
thread), in one command and one table.

    .venv/bin/python -m benchmarks.molecules_peers [--seeds 0-19] [--peers NAMES] [--out molecule-results]
                                                   [--table benchmarks/results/molecules_peers.md]

BayBE runs in its own environment: `../shared/peers/install_peer.sh baybe`, then
`/tmp/peervenvs/baybe/bin/pip install "baybe[chem]==0.15.0"` (its SubstanceParameter encodings need the chem extra).
Runs are stored by the harness under --out and skipped when present, so an interrupted run resumes.

Columns: the best (lowest) reduction potential found by experiment 20 and by experiment 40, as its distance above the
best molecule's (V; 0 = found); how many seeds found the best molecule by then; the median number of experiments to it
(41 where not found); the median CPU seconds of an ask and of the set-up (building the planner or campaign, where the
descriptors are computed).
"""

from __future__ import annotations

import argparse
import csv
import json
import statistics
import sys
from pathlib import Path

from benchmarks.portfolio import PEERS_DIR, VENVS, job, seeds_of

if str(PEERS_DIR) not in sys.path:  # the harness's `problems`, which the task module builds on
    sys.path.insert(0, str(PEERS_DIR))
from benchmarks.molecule_tasks import Btz57  # noqa: E402

OURS = sys.executable
PEERS = {
    "gryffin_ros_molecules": ("gryffin_ros default, SMILES options, RDKit default descriptors", OURS),
    "gryffin_ros_default": ("gryffin_ros default, the options alone (names)", OURS),
    "baybe_mordred": ("BayBE 0.15, SubstanceParameter, MORDRED (BayBE's default encoding)", "baybe"),
    "baybe_rdkit": ("BayBE 0.15, SubstanceParameter, RDKIT2DDESCRIPTORS", "baybe"),
    "baybe_onehot": ("BayBE 0.15, CategoricalParameter, one-hot", "baybe"),
    "random": ("random choice without repeats", OURS),
}
TASK = "btz57"
CHECKPOINTS = (20, 40)


def python_of(venv: str) -> str:
    return venv if venv == OURS else str(VENVS / venv / "bin" / "python")


def mean_and_error(values: list[float]) -> str:
    error = statistics.stdev(values) / len(values) ** 0.5 if len(values) > 1 else float("nan")
    return f"{statistics.mean(values):.3f} ± {error:.3f}"


def summarize(out: Path, peer: str, seeds: list[int], optimum: float, budget: int) -> list[str] | None:
    runs = []
    for seed in seeds:
        base = out / TASK / f"{peer}_seed{seed}"
        if not base.with_suffix(".json").exists():
            continue
        summary = json.loads(base.with_suffix(".json").read_text())
        if summary.get("error"):
            raise RuntimeError(f"{peer} seed {seed}: {summary['error']}")
        with open(base.with_suffix(".csv"), newline="") as handle:
            rows = list(csv.DictReader(handle))
        runs.append((summary, [float(r["best"]) for r in rows]))
    if not runs:
        return None
    cells = [str(len(runs))]
    for checkpoint in CHECKPOINTS:
        gaps = [best[min(checkpoint, len(best)) - 1] - optimum for _, best in runs]
        cells += [mean_and_error(gaps), f"{sum(g == 0 for g in gaps)}/{len(runs)}"]
    cells.append(f"{statistics.median(s['evals_to_opt'] or budget + 1 for s, _ in runs):g}")
    cells.append(f"{statistics.median(s['ask_cpu_median_s'] for s, _ in runs):.3f}")
    cells.append(f"{statistics.median(s['init_s'] for s, _ in runs):.2f}")
    return cells


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="0-19")
    parser.add_argument("--peers", default=",".join(PEERS))
    parser.add_argument("--out", type=Path, default=Path("molecule-results"))
    parser.add_argument("--table", type=Path,
                        default=Path(__file__).resolve().parent / "results" / "molecules_peers.md")
    args = parser.parse_args()
    seeds, peers = seeds_of(args.seeds), args.peers.split(",")
    for peer in peers:
        print(job(peer, python_of(PEERS[peer][1]), [TASK], seeds, args.out.resolve(), "molecule_tasks"), flush=True)
    task = Btz57()
    lines = [f"# Molecules side by side: the {len(task.names)} BTZ molecules, lowest reduction potential "
             f"(best {task.optimum:.4f} V), {task.budget} experiments incl. {task.n_init} common random ones, seeds "
             f"{args.seeds}", "",
             "| peer | seeds | gap at 20 (V) | found by 20 | gap at 40 (V) | found by 40 | median experiments to the "
             "best | ask CPU s (median) | set-up s |", "|---|---|---|---|---|---|---|---|---|"]
    for peer in peers:
        cells = summarize(args.out, peer, seeds, task.optimum, task.budget)
        if cells:
            lines.append(f"| {PEERS[peer][0]} | " + " | ".join(cells) + " |")
    text = "\n".join(lines) + "\n"
    args.table.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
