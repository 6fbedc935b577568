"""Median ask() latency of the Planner vs the number of observations n and the dimension d (paper SI setup: all
parameters continuous in [0, 1], optionally constrained by sum(x) <= 0.5 d), for the Adam and Genetic optimizers.

    python benchmarks/ask_latency.py [--repeats 5] [--out benchmarks/results/ask_latency.md]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np
import torch

from gryffin_ros.planner import Planner

GRID = [(n, 2) for n in (10, 30, 100, 300, 1000)] + [(100, d) for d in (5, 10, 20)] + [(1000, 10)]


def objective(x: np.ndarray) -> float:
    return float(np.sum(np.sin(5 * x) + x ** 2))


def median_ask(n: int, d: int, optimizer: str, constrained: bool, repeats: int, seed: int = 0) -> float:
    config = {
        "parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(d)],
        "objectives": [{"name": "y", "goal": "min"}],
        "general": {"acquisition_optimizer": optimizer},
        "constraints": [" + ".join(f"x{i}" for i in range(d)) + f" <= {0.5 * d}"] if constrained else [],
    }
    planner = Planner(config, seed=seed)
    rng = np.random.default_rng(seed)
    X = rng.random((4 * n, d))
    if constrained:
        X = X[X.sum(axis=1) <= 0.5 * d]
    X = X[:n]
    planner.tell([{**{f"x{i}": float(v) for i, v in enumerate(x)}, "y": objective(x)} for x in X])
    _ = planner.feasible_fraction  # estimated once per campaign, not per ask
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        (proposal,) = planner.ask()
        times.append(time.perf_counter() - start)
        x = np.array([proposal.params[f"x{i}"] for i in range(d)])
        planner.tell({**proposal.params, "y": objective(x), "experiment_id": proposal.experiment_id})
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "ask_latency.md")
    args = parser.parse_args()
    rows = ["| n | d | Adam | Adam, constrained | Genetic | Genetic, constrained |", "|---|---|---|---|---|---|"]
    for n, d in GRID:
        cells = [f"{median_ask(n, d, opt, c, args.repeats):.3f}" for opt in ("adam", "genetic") for c in (False, True)]
        rows.append(f"| {n} | {d} | " + " | ".join(cells) + " |")
        print(rows[-1], flush=True)
    header = (f"Median ask() seconds over {args.repeats} asks; {platform.processor() or platform.machine()}, "
              f"{os.cpu_count()} cores, torch {torch.__version__} ({torch.get_num_threads()} threads).\n\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(header + "\n".join(rows) + "\n")
    print(f"written to {args.out}")


if __name__ == "__main__":
    main()
