"""One campaign of the default planner on a portfolio task, experiment by experiment: the point (option names, the
conditions), its result, and what made the proposal (the surrogate, and the rules in its `meta`: covering, settled,
stalled, within, off_bound). How the worst seeds of benchmarks/README.md's tables are traced.

    python -m benchmarks.trace --task m_oxidation --seed 2 [--scratch] [--hidden] [--budget N]

Without --scratch the campaign starts as the peer harness's does (`python -m benchmarks.portfolio ... --ours
default`): the task's initial points of that seed told first, so it is that run's campaign of the default planner,
experiment for experiment. With --scratch it is `python -m benchmarks.from_scratch`'s campaign of that seed (with
--hidden, under its hidden failures). The last line: the best result, and the plain regret (best - reference,
`from_scratch.REFERENCES`) where the task has a reference.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# the harness's `problems`, which the tasks build on (as in portfolio.py)
sys.path.insert(0, os.environ.get("PEERS_DIR", str(ROOT.parent / "shared" / "peers")))

from benchmarks import portfolio_tasks  # noqa: E402
from benchmarks.from_scratch import HIDDEN, REFERENCES, hidden_failure, steps  # noqa: E402

RULES = ("covering", "settled", "stalled", "within", "off_bound")  # the proposal meta keys of the default's rules


def describe(task, x: list) -> str:
    """A harness point as `name=value` pairs: option names for categorical parameters, conditions to 4 digits."""
    out = []
    for p, v in zip(task.params, x):
        if getattr(p, "categorical", False):
            out.append(f"{p.name}={p.options[int(v)]}")
        elif p.kind == "int":
            out.append(f"{p.name}={int(v)}")
        else:
            out.append(f"{p.name}={v:.4g}")
    return " ".join(out)


def lines(task, seed: int, scratch: bool = False, hidden: bool = False, budget: int | None = None):
    """The campaign's lines as printed (see the module's docstring), the summary last."""
    initial = [] if scratch else task.initial_points(seed)
    best = math.inf
    for experiment, x, y, meta in steps(task, seed, budget or task.budget,
                                        lambda _, x: hidden and hidden_failure(task, x), initial):
        source = "initial" if experiment <= len(initial) else meta.get("surrogate", "")
        rules = " ".join(rule for rule in RULES if rule in meta)
        result = "failed" if y is None else f"{y:.4f}"
        best = best if y is None else min(best, y)
        yield f"{experiment:3d} {source:8s} {describe(task, x)}  {result}  {rules}".rstrip()
    summary = f"best {best:.4f}"
    if task.name in REFERENCES and math.isfinite(best):
        summary += f", regret {best - REFERENCES[task.name]:.4f}"
    yield summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--task", required=True, help="one of: " + ", ".join(portfolio_tasks.TASKS))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--scratch", action="store_true", help="from the planner's first proposal, no initial points")
    parser.add_argument("--hidden", action="store_true", help="the hidden failures of from_scratch.py")
    parser.add_argument("--budget", type=int, default=None, help="experiments in all (default: the task's)")
    args = parser.parse_args()
    if args.task not in portfolio_tasks.TASKS:
        parser.error(f"unknown task {args.task!r}; choose from {', '.join(portfolio_tasks.TASKS)}")
    if args.hidden and args.task not in HIDDEN:
        parser.error(f"--hidden is defined for {', '.join(HIDDEN)} only")
    if args.budget is not None and args.budget < 1:
        parser.error("--budget must be at least 1")
    for line in lines(portfolio_tasks.TASKS[args.task](), args.seed, args.scratch, args.hidden, args.budget):
        print(line, flush=True)


if __name__ == "__main__":
    main()
