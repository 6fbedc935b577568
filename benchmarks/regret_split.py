"""Where a campaign's regret lies: in the combination of options it ended on, or in the conditions it left within it.

For each stored harness campaign of a task (`python -m benchmarks.portfolio ... --out DIR` writes
DIR/<task>/<peer>_seed<k>.csv), the best successful experiment's combination (its categorical and discrete values) is
optimized over the continuous conditions alone (scipy's differential evolution, two seeds, the task's known constraints
as a penalty), and the plain regret (best - reference, `from_scratch.REFERENCES`) is split into that combination's
own gap to the reference and what the campaign left within it:

    python -m benchmarks.regret_split --task m_raft --runs DIR [--peer gryffin_ros_default]

Per seed: regret = combination + within; then the mean regret, the share of it from the combinations, the campaigns
whose combination is within 0.01 of the best, and the worst seed. A rule about options (covering, settled swaps) can
only reduce the first part. benchmarks/README.md, round thirty-one.
"""

from __future__ import annotations

import argparse
import csv
import functools
import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, os.environ.get("PEERS_DIR", str(ROOT.parent / "shared" / "peers")))

from benchmarks import portfolio_tasks  # noqa: E402
from benchmarks.from_scratch import REFERENCES  # noqa: E402

# differential evolution per combination: its population (per continuous condition) and generations; a point that
# breaks a known constraint scores PENALTY (far above any feasible value of the tasks of from_scratch.REFERENCES)
POPULATION, GENERATIONS, PENALTY = 25, 300, 1e3
CLOSE = 0.01  # a combination this close to the best counts as the best one


class Splitter:
    """The best value of each combination of a task's finite (categorical and discrete) parameters over its
    continuous ones, computed once per combination."""

    def __init__(self, task):
        self.task = task
        self.finite = [i for i, p in enumerate(task.params) if getattr(p, "categorical", False) or p.kind == "int"]
        self.continuous = [i for i in range(len(task.params)) if i not in self.finite]
        self.best_of = functools.lru_cache(maxsize=None)(self._best_of)

    def _best_of(self, combination: tuple[int, ...]) -> float:
        from scipy.optimize import differential_evolution

        def value(u):
            x = [0.0] * len(self.task.params)
            for i, v in zip(self.finite, combination):
                x[i] = v
            for i, v in zip(self.continuous, u):
                x[i] = float(v)
            return self.task.objective(x) if self.task.feasible(x) else PENALTY

        bounds = [(self.task.params[i].low, self.task.params[i].high) for i in self.continuous]
        if not bounds:
            return value([])
        return min(differential_evolution(value, bounds, seed=seed, popsize=POPULATION, maxiter=GENERATIONS,
                                          tol=1e-10, polish=False).fun for seed in range(2))

    def split(self, best_x: list[float], best: float, reference: float) -> tuple[float, float, tuple[int, ...]]:
        """-> (the combination's gap to the reference, what was left within it, the combination) of a campaign whose
        best successful experiment is best_x (harness point) with value `best`."""
        combination = tuple(int(round(best_x[i])) for i in self.finite)
        own = self.best_of(combination)
        return own - reference, best - own, combination


def campaigns(runs: Path, task, peer: str) -> list[tuple[int, list[float], float]]:
    """(seed, best successful point, its value) of each stored campaign of `peer` on `task`, by seed."""
    out = []
    for path in (runs / task.name).glob(f"{peer}_seed*.csv"):
        seed = int(re.search(r"_seed(\d+)\.csv$", path.name).group(1))
        with open(path, newline="") as fh:
            rows = [r for r in csv.DictReader(fh) if r["y"] not in ("", None)]
        if not rows:
            continue
        row = min(rows, key=lambda r: float(r["y"]))
        out.append((seed, [float(row[p.name]) for p in task.params], float(row["y"])))
    return sorted(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--task", required=True, help="one of " + ", ".join(REFERENCES))
    parser.add_argument("--runs", required=True, type=Path, help="the harness's --out folder")
    parser.add_argument("--peer", default="gryffin_ros_default")
    args = parser.parse_args()
    if args.task not in REFERENCES:
        parser.error(f"unknown task {args.task!r}; choose from {list(REFERENCES)}")
    task = portfolio_tasks.TASKS[args.task]()
    found = campaigns(args.runs, task, args.peer)
    if not found:
        parser.error(f"no campaigns of {args.peer} in {args.runs / args.task}")
    splitter, reference = Splitter(task), REFERENCES[args.task]
    rows = []
    for seed, x, best in found:
        gap, within, combination = splitter.split(x, best, reference)
        rows.append((seed, best - reference, gap, within))
        names = task.names(combination) if hasattr(task, "names") else combination
        print(f"seed {seed}: regret {best - reference:.4f} = combination {gap:.4f} + within {within:.4f}  {names}")
    total = sum(r[1] for r in rows)
    worst = max(rows, key=lambda r: r[1])
    share = sum(max(r[2], 0.0) for r in rows) / total if total > 0 else 0.0
    print(f"{args.task}, {len(rows)} campaigns: mean regret {total / len(rows):.4f}; share from the combination "
          f"{share:.2f}; on a combination within {CLOSE} of the best {sum(r[2] < CLOSE for r in rows)}; worst seed "
          f"{worst[0]}: {worst[1]:.4f} = {worst[2]:.4f} + {worst[3]:.4f}")


if __name__ == "__main__":
    main()
