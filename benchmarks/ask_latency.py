"""Median ask() latency of the Planner vs the number of observations n and the dimension d (paper SI setup: all
parameters continuous in [0, 1], optionally constrained by sum(x) <= 0.5 d), for the Adam and Genetic optimizers.

    python -m benchmarks.ask_latency [--repeats 5] [--surrogate kde] [--out benchmarks/results/ask_latency.md]

--surrogate: general.surrogate of every planner (default kde, the paper's model, which the stored tables measure; the
default portfolio at lab scale: benchmarks/lab_scale.py).

With --applications: the shipped examples instead (flow reactor, redox candidates with dynamic and static
descriptors), after n random feasible experiments measured by their emulators
(default out benchmarks/results/ask_latency_applications.md).
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


def median_ask(n: int, d: int, optimizer: str, constrained: bool, repeats: int, seed: int = 0,
               surrogate: str = "kde") -> float:
    config = {
        "parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(d)],
        "objectives": [{"name": "y", "goal": "min"}],
        "general": {"acquisition_optimizer": optimizer, "surrogate": surrogate},
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
    return median_timed_asks(planner, repeats, lambda params: {
        **params, "y": objective(np.array([params[f"x{i}"] for i in range(d)]))})


def median_timed_asks(planner: Planner, repeats: int, measured) -> float:
    """Median seconds of `repeats` ask() calls, each proposal told back as `measured(params)`."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        (proposal,) = planner.ask()
        times.append(time.perf_counter() - start)
        planner.tell({**measured(proposal.params), "experiment_id": proposal.experiment_id})
    return statistics.median(times)


def median_application_ask(example: str, general: dict, n: int, repeats: int, seed: int = 0,
                           surrogate: str = "kde") -> float:
    """Median ask() seconds of a shipped example after n random feasible experiments measured by its emulator."""
    from gryffin_ros.emulators import FlowReactorEmulator, RedoxEmulator
    from gryffin_ros.paths import share_path
    from gryffin_ros.planner.config import load_config, read_config
    examples = share_path("examples")
    config = read_config(examples / example)
    config["general"].update({"surrogate": surrogate, **general})
    planner = Planner(load_config(config, examples), seed=seed)
    emulator = FlowReactorEmulator(seed=seed) if example.startswith("flow") else RedoxEmulator()
    names = [o.name for o in planner.objectives]

    def measured(params: dict) -> dict:
        result = emulator.measure(params)
        return {**params, **{k: result[k] for k in names}}

    rng = np.random.default_rng(seed)
    points = planner.random_points(n, rng, np.empty((0, planner.space.dim)))
    planner.tell([measured(params) for params in planner.space.to_params(points)])
    return median_timed_asks(planner, repeats, measured)


APPLICATIONS = [("flow reactor, Genetic (the example)", "flow_reactor.yaml", {}),
                ("flow reactor, Adam", "flow_reactor.yaml", {"acquisition_optimizer": "adam"}),
                ("redox, dynamic descriptors (the example)", "redox_flow_battery.yaml", {}),
                ("redox, static descriptors", "redox_flow_battery.yaml", {"auto_desc_gen": False})]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--applications", action="store_true", help="the shipped examples instead of the grid")
    parser.add_argument("--surrogate", default="kde")
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    results = Path(__file__).parent / "results"
    if args.applications:
        args.out = args.out or results / "ask_latency_applications.md"
        rows = ["| example | n = 30 | n = 100 |", "|---|---|---|"]
        for label, example, general in APPLICATIONS:
            cells = [f"{median_application_ask(example, general, n, args.repeats, surrogate=args.surrogate):.3f}"
                     for n in (30, 100)]
            rows.append(f"| {label} | " + " | ".join(cells) + " |")
            print(rows[-1], flush=True)
    else:
        args.out = args.out or results / "ask_latency.md"
        rows = ["| n | d | Adam | Adam, constrained | Genetic | Genetic, constrained |", "|---|---|---|---|---|---|"]
        for n, d in GRID:
            cells = [f"{median_ask(n, d, opt, c, args.repeats, surrogate=args.surrogate):.3f}"
                     for opt in ("adam", "genetic")
                     for c in (False, True)]
            rows.append(f"| {n} | {d} | " + " | ".join(cells) + " |")
            print(rows[-1], flush=True)
    header = (f"Median ask() seconds over {args.repeats} asks, surrogate {args.surrogate}; "
              f"{platform.processor() or platform.machine()}, "
              f"{os.cpu_count()} cores, torch {torch.__version__} ({torch.get_num_threads()} threads).\n\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(header + "\n".join(rows) + "\n")
    print(f"written to {args.out}")


if __name__ == "__main__":
    main()
