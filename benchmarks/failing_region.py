"""A hidden failing region: a smooth 2-d objective whose best feasible point sits at the edge of a quarter of the
domain (x0 > 0.5 and x1 > 0.5) where every experiment fails (reported as None); the planner is not told. 60
experiments per run, the first ones the planner's random initialization; reports how many of experiments 31-60 went
inside the region (uniform sampling: 25 %), per run and in all.

    python -m benchmarks.failing_region [--seeds 5] [--feas-model kde|gp] [--surrogate kde|gp|auto|portfolio]
"""

from __future__ import annotations

import argparse
import math
import statistics

EXPERIMENTS, LATE = 60, 30
SQUARE = {"parameters": [{"name": n, "type": "continuous", "low": 0.0, "high": 1.0} for n in ("x0", "x1")],
          "objectives": [{"name": "y", "goal": "min"}]}


def inside(x0: float, x1: float) -> bool:
    return x0 > 0.5 and x1 > 0.5


def objective(x0: float, x1: float) -> float:
    """Smooth, its minimum near (0.45, 0.6): just outside the failing quarter, so the planner is drawn to its edge."""
    return (x0 - 0.45) ** 2 + (x1 - 0.6) ** 2 + 0.02 * math.sin(12 * x0) * math.cos(9 * x1)


def best_feasible(steps: int = 1001) -> float:
    """The objective's minimum outside the failing region, on a dense grid (the region's edge included)."""
    import numpy as np
    x0, x1 = np.meshgrid(np.linspace(0, 1, steps), np.linspace(0, 1, steps))
    values = (x0 - 0.45) ** 2 + (x1 - 0.6) ** 2 + 0.02 * np.sin(12 * x0) * np.cos(9 * x1)
    return float(values[~((x0 > 0.5) & (x1 > 0.5))].min())


def run(seed: int, general: dict) -> tuple[int, float]:
    """-> (experiments LATE + 1 .. EXPERIMENTS inside the failing region, best result)."""
    import torch

    from gryffin_ros.planner import Planner
    torch.set_num_threads(1)
    planner = Planner({**SQUARE, "general": general}, seed=seed)
    late, best = 0, math.inf
    for experiment in range(1, EXPERIMENTS + 1):
        (proposal,) = planner.ask()
        x0, x1 = proposal.params["x0"], proposal.params["x1"]
        failed = inside(x0, x1)
        late += failed and experiment > LATE
        best = best if failed else min(best, objective(x0, x1))
        planner.tell({**proposal.params, "y": None if failed else objective(x0, x1),
                      "experiment_id": proposal.experiment_id})
    return late, best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--feas-model", default=None, help="general.feas_model (default: the planner's)")
    parser.add_argument("--surrogate", default=None, help="general.surrogate (default: the planner's)")
    parser.add_argument("--feas-approach", default=None, help="general.feas_approach (default: the planner's)")
    args = parser.parse_args()
    general = {k: v for k, v in (("feas_model", args.feas_model), ("surrogate", args.surrogate),
                                 ("feas_approach", args.feas_approach)) if v is not None}
    optimum = best_feasible()
    counts, regrets = [], []
    for seed in range(args.seeds):
        count, best = run(seed, general)
        counts.append(count)
        regrets.append(best - optimum)
        print(f"seed {seed}: {count} of experiments {LATE + 1}-{EXPERIMENTS} inside, regret {regrets[-1]:.2e}",
              flush=True)
    share = [100.0 * c / (EXPERIMENTS - LATE) for c in counts]
    se = statistics.stdev(share) / math.sqrt(len(share)) if len(share) > 1 else float("nan")
    print(f"{general or 'default'}: {statistics.mean(share):.1f} ± {se:.1f} % of experiments {LATE + 1}-{EXPERIMENTS} "
          f"inside the failing region, {args.seeds} seeds; regret (best - {optimum:.5f}) median "
          f"{statistics.median(regrets):.2e}, worst {max(regrets):.2e}")


if __name__ == "__main__":
    main()
