"""Time per recommendation against the feasible fraction: rejection sampling alone vs rejection plus the hit-and-run
sampler (issue 8). The feasible set is a ball in [0, 1]^d (a non-linear constraint) or the corner simplex
sum(x) <= s (a linear one, so hit-and-run chords are exact) of volume fraction 1e-1 ... 1e-6; the campaign starts
from one experiment the chemist knows is feasible (the ball's centre; near the simplex's corner), then runs `--asks`
ask/tell rounds on a quadratic objective with its minimum inside (off-centre in the ball; the simplex's centroid).

    python -m benchmarks.tiny_regions [--dims 4 6] [--asks 8] [--out benchmarks/results]

"Rejection only" is the planner with the hit-and-run sampler switched off (its `walk` replaced, for this comparison
only): start points are then uniform draws (at most general.max_rejection_draws per call) and ±5 % perturbations of
the best experiment.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import statistics
import time
from pathlib import Path

import numpy as np
import torch

from gryffin_ros.planner import GryffinRosError, Planner

FRACTIONS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)


def radius_for(fraction: float, d: int) -> float:
    """Radius of the d-ball of volume `fraction`."""
    return (fraction * math.gamma(d / 2 + 1) / math.pi ** (d / 2)) ** (1.0 / d)


def campaign(d: int, fraction: float, asks: int, walk: bool, shape: str = "ball", seed: int = 0) -> dict:
    names = [f"x{i}" for i in range(d)]
    config = {"parameters": [{"name": n, "type": "continuous", "low": 0, "high": 1} for n in names],
              "objectives": [{"name": "y", "goal": "min"}],
              "general": {"surrogate": "kde"}}  # the model the stored tables measured (start points are shared)
    if shape == "ball":
        r = radius_for(fraction, d)
        centre = 0.5
        config["constraints"] = [" + ".join(f"({n} - {centre}) ** 2" for n in names) + f" <= {r * r!r}"]
        target = np.full(d, centre + 0.5 * r / math.sqrt(d))
        inside_fn = lambda x: np.linalg.norm(x - centre) <= r * (1 + 1e-12)  # noqa: E731
    else:  # the corner simplex sum(x) <= s, volume s^d / d!: a linear constraint (exact hit-and-run chords)
        r = (fraction * math.factorial(d)) ** (1.0 / d)
        centre = r / (4 * d)  # the known experiment, near the corner
        config["constraints"] = [" + ".join(names) + f" <= {r!r}"]
        target = np.full(d, r / (d + 1))  # the centroid
        inside_fn = lambda x: x.sum() <= r * (1 + 1e-12)  # noqa: E731
    planner = Planner(config, seed=seed)
    if not walk:  # rejection sampling alone: the planner's walk inside the feasible region returns nothing
        planner.region.walk = lambda constraints, rng, seeds, m, **kw: np.empty((0, constraints.space.dim))
    planner.tell({**{f"x{i}": centre for i in range(d)}, "y": float(((centre - target) ** 2).sum())})
    times, inside, error = [], 0, None
    for _ in range(asks):
        tick = time.perf_counter()
        try:
            (proposal,) = planner.ask()
        except GryffinRosError as exc:
            error = f"{type(exc).__name__}: {str(exc)[:80]}"
            times.append(time.perf_counter() - tick)
            break
        times.append(time.perf_counter() - tick)
        x = np.array([proposal.params[f"x{i}"] for i in range(d)])
        inside += bool(inside_fn(x))
        planner.tell({**proposal.params, "y": float(((x - target) ** 2).sum()),
                      "experiment_id": proposal.experiment_id})
    best = planner.best().objectives["y"]
    return {"d": d, "shape": shape, "fraction": fraction, "walk": walk, "median_ask": statistics.median(times),
            "max_ask": max(times), "proposals": len(planner.observations) - 1, "inside": inside, "error": error,
            "best_over_r2": best / (r * r)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dims", type=int, nargs="+", default=[4, 6])
    parser.add_argument("--asks", type=int, default=8)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    args = parser.parse_args()
    torch.set_num_threads(1)
    rows, results = [], []
    for shape, d, fraction, walk in itertools.product(("ball", "simplex"), args.dims, FRACTIONS, (False, True)):
        result = campaign(d, fraction, args.asks, walk, shape)
        results.append(result)
        row = (f"| {shape} | {d} | {fraction:.0e} | {'rejection + hit-and-run' if walk else 'rejection only'} | "
               f"{result['median_ask']:.3f} | {result['max_ask']:.3f} | "
               f"{result['inside']}/{result['proposals']} | {result['best_over_r2']:.3f} | "
               f"{result['error'] or ''} |")
        rows.append(row)
        print(row, flush=True)
    lines = ["# Tiny feasible regions: seconds per recommendation vs feasible fraction", "",
             f"Command: `python -m benchmarks.tiny_regions --asks {args.asks}` (one thread). A ball (radius r) or "
             "corner simplex sum(x) <= r of the given volume fraction in [0, 1]^d, one known feasible experiment "
             "inside, then ask/tell rounds; 'best / r^2': best objective relative to r^2 (lower is better; the "
             "minimum is 0; the known experiment scores 0.25 in the ball, 0.076 (d = 4) / 0.061 (d = 6) in the "
             "simplex).", "",
             "| shape | d | feasible fraction | start points | median ask (s) | max ask (s) | proposals inside | "
             "best / r^2 | error |", "|---|---|---|---|---|---|---|---|---|", *rows]
    (args.out / "tiny_regions.md").write_text("\n".join(lines) + "\n")
    (args.out / "tiny_regions.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
