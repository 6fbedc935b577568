"""A hidden failing region: a smooth 2-d objective on the unit square and a region where every experiment fails
(reported as None); the planner is not told. 60 experiments per run, the first ones the planner's random
initialization; reports how many of experiments 31-60 went inside the region, and how many of those lay deep inside
(every point within DEEP of them fails too: not a probe of the region's edge), per run and in all.

Regions (--region):
- edge (the default): the quarter x0 > 0.5 and x1 > 0.5; the best feasible point at (0.42, 0.64), beside its edge.
- branin: Branin (rescaled to the unit square, / 100) with the quarter x0 > 0.5 and x1 < 0.5 failing: two of its
  three minima inside; the third, (0.124, 0.818), is the best feasible point.
- holds-optimum: (x0 - 0.65)^2 + (x1 - 0.7)^2 with the quarter x0 > 0.5 and x1 > 0.5 failing: the unconstrained
  optimum inside, the best feasible points on the region's edge (where about half of any probes fail).
- camel: the six-hump camel (x0 on [-3, 3], x1 on [-2, 2]) with the quarter x0 > 0.5 and x1 < 0.5 failing: one of
  its two global minima inside, 0.015 from the region's edge; the other, (0.485, 0.678), feasible.
- camel-open: the six-hump camel with no failing region; with --failure-rate, failures at random only.

Three more, added after the default's failure handling was tuned (round fourteen of benchmarks/README.md), to see
whether it carries over to shapes it was not tuned on:
- himmelblau: Himmelblau's function (x0, x1 -> [-5, 5], / 100) with the quarter x0 > 0.5 and x1 > 0.5 failing: one
  of its four global minima (0.8, 0.7) inside, the other three feasible.
- disc: a disc of radius 0.25 around (0.37, 0.32) fails (not axis-aligned); a bowl with a wave whose minimum,
  (0.593, 0.45), lies 0.008 outside the disc.
- diagonal: the half-square x0 + x1 > 1 fails (an oblique edge); (x0 - 0.6)^2 + 2 (x1 - 0.5)^2 has its minimum
  inside, the best feasible point (0.533, 0.467) on the edge (as holds-optimum: probes of it fail about half the time).

With --failure-rate R every experiment also fails with probability R wherever it is (an instrument's random failures;
drawn from a generator seeded by the run's seed, the same draws whatever the planner proposes). The last line then
also counts the runs that ended STUCK_REGRET or more short of the best feasible value (on the camel: on one of its
local minima, -0.2155, regret 0.82, instead of a global one).

With --dims D > 2 the square becomes the unit cube of D dims: the region fails by x0 and x1 alone (a slab), and
each further coordinate adds EXTRA_WEIGHT (x_i - EXTRA_CENTRE)^2 to the objective, so the optimum's value stays.

    python -m benchmarks.failing_region [--seeds 5]
                                        [--region edge|branin|holds-optimum|camel|camel-open|himmelblau|disc|diagonal]
                                        [--feas-model kde|gp] [--surrogate kde|gp|auto|portfolio]
                                        [--feas-approach fwt|fwa|fia|fca] [--dims 2] [--failure-rate 0]
"""

from __future__ import annotations

import argparse
import math
import statistics

from benchmarks.surfaces import branin

EXPERIMENTS, LATE = 60, 30
EXTRA_WEIGHT, EXTRA_CENTRE = 0.5, 0.4


def cube(dims: int = 2) -> dict:
    """The planner's config: `dims` continuous parameters x0, x1, ... on [0, 1], one objective to minimize."""
    return {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(dims)],
            "objectives": [{"name": "y", "goal": "min"}]}


def inside(x0: float, x1: float) -> bool:
    return x0 > 0.5 and x1 > 0.5


def objective(x0: float, x1: float) -> float:
    """Smooth, its minimum near (0.45, 0.6): just outside the failing quarter, so the planner is drawn to its edge."""
    return (x0 - 0.45) ** 2 + (x1 - 0.6) ** 2 + 0.02 * math.sin(12 * x0) * math.cos(9 * x1)


def six_hump_camel(x0: float, x1: float) -> float:
    """The six-hump camel on the unit square (x0 -> [-3, 3], x1 -> [-2, 2]): minima -1.0316 at (0.485, 0.678) and
    (0.515, 0.322), four local ones around them."""
    x, y = 6 * x0 - 3, 4 * x1 - 2
    return (4 - 2.1 * x * x + x ** 4 / 3) * x * x + x * y + (4 * y * y - 4) * y * y


def himmelblau(x0: float, x1: float) -> float:
    """Himmelblau's function on the unit square (x0, x1 -> [-5, 5]) / 100: four global minima 0, at (0.8, 0.7),
    (0.2195, 0.8131), (0.1221, 0.1717) and (0.8584, 0.3152)."""
    x, y = 10 * x0 - 5, 10 * x1 - 5
    return ((x * x + y - 11) ** 2 + (x + y * y - 7) ** 2) / 100


def wavy_bowl(x0: float, x1: float) -> float:
    """A bowl with a wave along x0: its minimum -0.0337 at (0.593, 0.45)."""
    return (x0 - 0.5) ** 2 + (x1 - 0.45) ** 2 + 0.05 * math.sin(7 * x0)


REGIONS = {  # name: (objective, fails)
    "edge": (objective, inside),
    "branin": (lambda x0, x1: float(branin(x0, x1)) / 100, lambda x0, x1: x0 > 0.5 and x1 < 0.5),
    "holds-optimum": (lambda x0, x1: (x0 - 0.65) ** 2 + (x1 - 0.7) ** 2, inside),
    "camel": (six_hump_camel, lambda x0, x1: x0 > 0.5 and x1 < 0.5),
    "camel-open": (six_hump_camel, lambda x0, x1: False),
    "himmelblau": (himmelblau, inside),
    "disc": (wavy_bowl, lambda x0, x1: (x0 - 0.37) ** 2 + (x1 - 0.32) ** 2 < 0.25 ** 2),
    "diagonal": (lambda x0, x1: (x0 - 0.6) ** 2 + 2 * (x1 - 0.5) ** 2, lambda x0, x1: x0 + x1 > 1.0),
}
DEEP = 0.03
STUCK_REGRET = 0.5
RANDOM_FAILURE_SEED = 1000  # + the run's seed: the generator of --failure-rate's draws


def deep(fails, x0: float, x1: float) -> bool:
    """Every point of the square of half-width DEEP around (x0, x1), corners and edge midpoints, fails."""
    return all(fails(x0 + a * DEEP, x1 + b * DEEP) for a in (-1, 0, 1) for b in (-1, 0, 1))


def best_feasible(region: str = "edge", steps: int = 1001) -> float:
    """The objective's minimum outside the failing region, on a dense grid (the region's edge included)."""
    import numpy as np
    f, fails = REGIONS[region]
    x0, x1 = np.meshgrid(np.linspace(0, 1, steps), np.linspace(0, 1, steps))
    values = np.vectorize(f)(x0, x1)
    return float(values[~np.vectorize(fails)(x0, x1)].min())


def failure_draws(seed: int, rate: float, experiments: int = EXPERIMENTS) -> list[bool]:
    """Which of a run's experiments fail at random (--failure-rate), whatever and wherever they are."""
    import numpy as np
    return (np.random.default_rng(RANDOM_FAILURE_SEED + seed).random(experiments) < rate).tolist()


def run(seed: int, general: dict, region: str = "edge", dims: int = 2, failure_rate: float = 0.0
        ) -> tuple[int, int, float]:
    """-> (experiments LATE + 1 .. EXPERIMENTS inside the failing region, those deep inside, best result); with
    failure_rate each experiment also fails with that probability, wherever it is."""
    import torch

    from gryffin_ros.planner import Planner
    torch.set_num_threads(1)
    f, fails = REGIONS[region]
    planner = Planner({**cube(dims), "general": general}, seed=seed)
    randomly = failure_draws(seed, failure_rate)
    late, late_deep, best = 0, 0, math.inf
    for experiment in range(1, EXPERIMENTS + 1):
        (proposal,) = planner.ask()
        x0, x1 = proposal.params["x0"], proposal.params["x1"]
        in_region = fails(x0, x1)
        late += in_region and experiment > LATE
        failed = in_region or randomly[experiment - 1]
        late_deep += deep(fails, x0, x1) and experiment > LATE
        y = f(x0, x1) + EXTRA_WEIGHT * sum((proposal.params[f"x{i}"] - EXTRA_CENTRE) ** 2 for i in range(2, dims))
        best = best if failed else min(best, y)
        planner.tell({**proposal.params, "y": None if failed else y, "experiment_id": proposal.experiment_id})
    return late, late_deep, best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--region", default="edge", choices=list(REGIONS))
    parser.add_argument("--feas-model", default=None, help="general.feas_model (default: the planner's)")
    parser.add_argument("--surrogate", default=None, help="general.surrogate (default: the planner's)")
    parser.add_argument("--feas-approach", default=None, help="general.feas_approach (default: the planner's)")
    parser.add_argument("--dims", type=int, default=2, help="continuous parameters (>= 2; see above)")
    parser.add_argument("--failure-rate", type=float, default=0.0, help="random failures anywhere (see above)")
    args = parser.parse_args()
    if args.dims < 2:
        parser.error("--dims must be at least 2: the regions are defined on x0 and x1")
    if not 0.0 <= args.failure_rate < 1.0:
        parser.error("--failure-rate must be in [0, 1)")
    general = {k: v for k, v in (("feas_model", args.feas_model), ("surrogate", args.surrogate),
                                 ("feas_approach", args.feas_approach)) if v is not None}
    optimum = best_feasible(args.region)
    counts, deeps, regrets = [], [], []
    for seed in range(args.seeds):
        count, count_deep, best = run(seed, general, args.region, args.dims, args.failure_rate)
        counts.append(count)
        deeps.append(count_deep)
        regrets.append(best - optimum)
        print(f"seed {seed}: {count} of experiments {LATE + 1}-{EXPERIMENTS} inside ({count_deep} deep), regret "
              f"{regrets[-1]:.2e}", flush=True)
    share = [100.0 * c / (EXPERIMENTS - LATE) for c in counts]
    share_deep = [100.0 * c / (EXPERIMENTS - LATE) for c in deeps]
    se = statistics.stdev(share) / math.sqrt(len(share)) if len(share) > 1 else float("nan")
    print(f"{args.region}{f' in {args.dims}-D' if args.dims > 2 else ''}, {general or 'default'}: "
          f"{statistics.mean(share):.1f} ± {se:.1f} % of experiments "
          f"{LATE + 1}-{EXPERIMENTS} inside the failing region ({statistics.mean(share_deep):.1f} % deep inside), "
          f"{args.seeds} seeds; regret (best - {optimum:.5f}) median {statistics.median(regrets):.2e}, "
          f"worst {max(regrets):.2e}"
          + (f"; random failures {args.failure_rate:g}: {sum(r >= STUCK_REGRET for r in regrets)} of {args.seeds} "
             f"runs {STUCK_REGRET:g} or more short" if args.failure_rate else ""))


if __name__ == "__main__":
    main()
