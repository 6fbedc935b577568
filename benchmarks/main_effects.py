"""The GP's main-effect terms (`main_effects_kernel`, #33 round nineteen) on two tasks they were not tuned on, each a
catalyst (5 options), a base (4) and an additive (4), all categorical with descriptors, + temperature and
concentration (a cap on their product), 40 experiments from the planner's first proposal, the default surrogate
(the portfolio: with two continuous parameters the kernel density first, the GP where it ranks the data better):

- `match`: interactions only. The yield is high where the base's descriptors match the catalyst's (swapped) and the
  additive's matches the catalyst's second one; no option is good on its own.
- `mult`: the rate is a product of one activity per option (main effects on the log scale) and of the conditions.

Each seed runs once with the kernel as shipped and once with one product kernel (MAIN_EFFECTS_MIN_PARAMETERS raised
above the number of parameters); plain regret (best - reference, a 41 x 41 grid over the conditions of every
combination), per seed, then mean, median, worst and the paired difference.

    python -m benchmarks.main_effects [--seeds 16] [--processes 2]
"""

from __future__ import annotations

import argparse
import itertools
import math
import os
import statistics
import sys
from multiprocessing import Pool
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, os.environ.get("PEERS_DIR", str(ROOT.parent / "shared" / "peers")))  # the harness's `problems`

from problems import CatParam, Param, Task  # noqa: E402

from benchmarks.from_scratch import campaign  # noqa: E402
from gryffin_ros.planner.surrogates.gaussian_process import MAIN_EFFECTS_MIN_PARAMETERS  # noqa: E402

CATALYSTS = {"c0": (0.1, 0.9), "c1": (0.4, 0.2), "c2": (0.8, 0.6), "c3": (0.95, 0.05), "c4": (0.3, 0.5)}
BASES = {"b0": (0.2, 0.3), "b1": (0.5, 0.9), "b2": (0.9, 0.4), "b3": (0.6, 0.1)}
ADDITIVES = {"a0": (0.1,), "a1": (0.45,), "a2": (0.7,), "a3": (1.0,)}


class ThreeOptions(Task):
    budget = 40

    def __init__(self):
        self.params = [CatParam("catalyst", list(CATALYSTS), CATALYSTS), CatParam("base", list(BASES), BASES),
                       CatParam("additive", list(ADDITIVES), ADDITIVES), Param("T", "float", 20.0, 120.0),
                       Param("conc", "float", 0.05, 1.0)]

    def options(self, x) -> tuple[str, str, str]:
        return list(CATALYSTS)[int(x[0])], list(BASES)[int(x[1])], list(ADDITIVES)[int(x[2])]

    def feasible(self, x):
        return x[3] * x[4] <= 90.0


class Match(ThreeOptions):
    name = "match"

    def objective(self, x):
        catalyst, base, additive = self.options(x)
        c, b, a = CATALYSTS[catalyst], BASES[base], ADDITIVES[additive]
        match = math.exp(-((b[0] - c[1]) ** 2 + (b[1] - c[0]) ** 2) / 0.08 - (a[0] - c[1]) ** 2 / 0.05)
        conditions = math.exp(-((x[3] - 40.0 - 60.0 * c[0]) / 30.0) ** 2) * (1 - math.exp(-4.0 * x[4]))
        return -(match * conditions - 0.05 * x[4])


class Mult(ThreeOptions):
    name = "mult"
    ACTIVITY = {"c0": 0.3, "c1": 0.9, "c2": 0.5, "c3": 0.7, "c4": 0.2, "b0": 0.4, "b1": 0.6, "b2": 1.0, "b3": 0.3,
                "a0": 0.8, "a1": 0.3, "a2": 1.0, "a3": 0.5}

    def objective(self, x):
        k = math.prod(self.ACTIVITY[o] for o in self.options(x))
        rate = 3.0 * k * x[4] * math.exp(0.03 * (x[3] - 60.0))
        return -((1 - math.exp(-rate)) * math.exp(-((x[3] - 70.0) / 50.0) ** 2) - 0.05 * x[4])


TASKS = {"match": Match, "mult": Mult}


def reference(task: ThreeOptions, steps: int = 41) -> float:
    best = math.inf
    for combination in itertools.product(*(range(len(p.options)) for p in task.params[:3])):
        for i, j in itertools.product(range(steps), repeat=2):
            x = [*combination, 20.0 + 100.0 * i / (steps - 1), 0.05 + 0.95 * j / (steps - 1)]
            if task.feasible(x):
                best = min(best, task.objective(x))
    return best


def run(job: tuple[str, int, bool]) -> tuple[str, int, bool, float]:
    """One campaign: (task, seed, main effects) -> the same and the best value."""
    from gryffin_ros.planner.surrogates import gaussian_process
    name, seed, main_effects = job
    # as shipped, or above the three parameters: one product kernel
    gaussian_process.MAIN_EFFECTS_MIN_PARAMETERS = MAIN_EFFECTS_MIN_PARAMETERS if main_effects else 4
    task = TASKS[name]()
    return name, seed, main_effects, campaign(task, seed, task.budget, lambda experiment, x: False)[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=16)
    parser.add_argument("--processes", type=int, default=2)
    args = parser.parse_args()
    jobs = [(t, s, m) for t in TASKS for m in (True, False) for s in range(args.seeds)]
    with Pool(args.processes) as pool:
        results = pool.map(run, jobs, chunksize=1)
    for t in TASKS:
        ref = reference(TASKS[t]())
        regret = {(s, m): best - ref for name, s, m, best in results if name == t}
        for m, label in ((False, "one product kernel"), (True, "main effects")):
            values = [regret[s, m] for s in range(args.seeds)]
            print(f"{t}, {label}: regret mean {statistics.mean(values):.4f}, median {statistics.median(values):.4f}, "
                  f"worst {max(values):.4f}; per seed " + " ".join(f"{v:.3f}" for v in values))
        diff = [regret[s, True] - regret[s, False] for s in range(args.seeds)]
        print(f"{t}, main effects - product, paired: {statistics.mean(diff):+.4f} ± "
              f"{statistics.stdev(diff) / math.sqrt(len(diff)):.4f} (better on {sum(d < -1e-3 for d in diff)} "
              f"seeds, worse on {sum(d > 1e-3 for d in diff)})")


if __name__ == "__main__":
    main()
