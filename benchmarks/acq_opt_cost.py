"""Cost of the constrained acquisition optimization (the paper's SI scaling study) next to Gryffin's published timings.

Objective ||x - 0.5||^2 on [0, 1]^d, observations drawn uniformly from the feasible set, constraint sum(x) <= 0.5 d
(or none); one thread, as the published runs (num_cpus = 1). Timed: the acquisition optimization for one sampling
strategy (start points + Adam/Hill or genetic refinement), for lambda = -1 and +1, and the whole ask (surrogate build,
both strategies, selection). Published: Gryffin's `proposals_opt` time per strategy, mean of 20 repeats, from
../shared/data/gkc_benchmarks/comp-scaling-acq-opt/DERIVED_timings.json (another machine; TensorFlow-era Gryffin).

    python -m benchmarks.acq_opt_cost [--repeats 5] [--data ../shared/data] [--out benchmarks/results]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np
import torch

from gryffin_ros.planner import Planner, vectorized
from gryffin_ros.planner.acquisition.kernel import Acquisition
from gryffin_ros.planner.strategies.gryffin import SPACING_FACTOR
from gryffin_ros.planner.surrogates.kernel_density import KernelDensity

DIMS = (1, 2, 3, 4, 6, 8, 10)
NUM_OBS = (10, 100, 200, 300, 400, 500)


def make_planner(d: int, n: int, constrained: bool, optimizer: str, seed: int) -> Planner:
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(d)],
              "objectives": [{"name": "y", "goal": "min"}],
              "general": {"acquisition_optimizer": optimizer, "surrogate": "kde"}}  # the paper's acquisition

    @vectorized
    def half_sum(columns):
        return sum(np.asarray(columns[f"x{i}"]) for i in range(d)) <= 0.5 * d

    planner = Planner(config, known_constraints=half_sum if constrained else None, seed=seed)
    rng = np.random.default_rng(seed)
    X = rng.random((20 * n + 100, d))
    if constrained:
        X = X[X.sum(axis=1) <= 0.5 * d]
    X = X[:n]
    planner.tell([{**{f"x{i}": float(x[i]) for i in range(d)}, "y": float(((x - 0.5) ** 2).sum())} for x in X])
    return planner


def time_case(d: int, n: int, constrained: bool, optimizer: str, repeats: int) -> dict:
    acq = {-1.0: [], 1.0: []}
    ask = []
    for r in range(repeats):
        planner = make_planner(d, n, constrained, optimizer, seed=r)
        rng = np.random.default_rng(r)
        X = planner.observed_points()
        merits = planner.merits(planner.observations)
        density = KernelDensity(planner.space, X, merits, planner.feasible_fraction.value,
                                torch.Generator().manual_seed(r), spacing_scaled=planner.spacing_kernels,
                                spacing_factor=SPACING_FACTOR)
        for s in acq:
            tick = time.perf_counter()
            start, _ = planner.start_points(rng, X[int(np.argmin(merits))], X)
            planner.optimizer().optimize(Acquisition(density, s), start, rng)
            acq[s].append(time.perf_counter() - tick)
        tick = time.perf_counter()
        planner.ask(2)
        ask.append(time.perf_counter() - tick)
    return {"acq_minus1": statistics.fmean(acq[-1.0]), "acq_plus1": statistics.fmean(acq[1.0]),
            "ask": statistics.fmean(ask)}


def published(data: Path) -> dict:
    raw = json.loads((data / "gkc_benchmarks" / "comp-scaling-acq-opt" / "DERIVED_timings.json").read_text())
    out = {}
    for name, table in raw.items():
        study, constraint, optimizer = name.removesuffix(".pkl").split("-")
        for size, per_strategy in table.items():
            out[(study, constraint, optimizer, int(size))] = {
                s: statistics.fmean(v) for s, v in per_strategy.items()}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--data", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "data")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    args = parser.parse_args()
    torch.set_num_threads(1)
    theirs = published(args.data)
    rows, results = [], []
    for study, sizes in (("dims", DIMS), ("num_obs", NUM_OBS)):
        for constraint in ("constrained", "unconstrained"):
            for optimizer in ("adam", "genetic"):
                for size in sizes:
                    d, n = (size, 100) if study == "dims" else (2, size)
                    ours = time_case(d, n, constraint == "constrained", optimizer, args.repeats)
                    pub = theirs.get((study, constraint, optimizer, size), {})
                    results.append({"study": study, "constraint": constraint, "optimizer": optimizer, "d": d, "n": n,
                                    **ours, "published_minus1": pub.get("-1"), "published_plus1": pub.get("1")})
                    row = results[-1]
                    rows.append(f"| {study} | {constraint} | {optimizer} | {d} | {n} | {row['acq_minus1']:.3f} | "
                                f"{row['acq_plus1']:.3f} | {row['ask']:.3f} | "
                                f"{row['published_minus1'] or float('nan'):.1f} | "
                                f"{row['published_plus1'] or float('nan'):.1f} |")
                    print(rows[-1], flush=True)
    lines = ["# Acquisition-optimization cost (paper SI scaling study)", "",
             f"Command: `python -m benchmarks.acq_opt_cost --repeats {args.repeats}` (one thread, 2-core machine). "
             "Seconds, mean over repeats. Ours: acquisition optimization for one strategy (start points + "
             "refinement) and the whole ask of 2 proposals; published: Gryffin's acquisition optimization per "
             "strategy, 20 repeats, another machine.", "",
             "| study | constraint | optimizer | d | n | ours acq lambda=-1 | ours acq lambda=+1 | ours whole ask | "
             "published lambda=-1 | published lambda=+1 |", "|---|---|---|---|---|---|---|---|---|---|", *rows]
    (args.out / "acq_opt_cost.md").write_text("\n".join(lines) + "\n")
    (args.out / "acq_opt_cost.json").write_text(json.dumps(results, indent=1))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, study, key in ((axes[0], "dims", "d"), (axes[1], "num_obs", "n")):
        for constraint, ls in (("constrained", "-"), ("unconstrained", ":")):
            for optimizer, color in (("adam", "C0"), ("genetic", "C1")):
                sel = [r for r in results if r["study"] == study and r["constraint"] == constraint
                       and r["optimizer"] == optimizer]
                x = [r[key] for r in sel]
                ax.plot(x, [r["acq_minus1"] for r in sel], ls=ls, color=color, marker="o",
                        label=f"ours {optimizer} {constraint}")
                ax.plot(x, [r["published_minus1"] for r in sel], ls=ls, color=color, marker="x", alpha=0.5,
                        label=f"Gryffin {optimizer} {constraint}")
        ax.set_yscale("log")
        ax.set_xlabel("dimensions (n = 100)" if study == "dims" else "observations (d = 2)")
        ax.set_ylabel("seconds per acquisition optimization")
    axes[0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(args.out / "acq_opt_cost.png", dpi=110)


if __name__ == "__main__":
    main()
