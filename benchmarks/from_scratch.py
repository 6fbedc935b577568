"""A campaign from the planner's first proposal: tasks of the portfolio (`portfolio_tasks.py`; the mixed ones, the
6-D Hartmann, the kinetics) without the peer harness's five random initial points, the way a lab starts one.
Optionally with hidden failures (`--hidden`): experiments that fail by rules the planner is not told, reported as
failed (`None`). With `--failure-rate R` each experiment also fails with probability R, wherever it is (a blocked line,
a cracked vial; the draws of failing_region.py's option).

Hidden failures (m_coupling, m_oxidation, m_hydrogenation, m_crystallization, m_electrochem, m_amide, m_raft and
m_metathesis),
touching no task's best combination, so the references stay the optima:
- m_coupling: every experiment with Cs2CO3 fails (the base precipitates) and every one in DMF above 110 deg C (the
  solvent decomposes); the best, PPh3 / K3PO4 / EtOH, runs at most at 73 deg C by the known constraint.
- m_oxidation: every experiment with AZADO fails (a degraded batch: the near-duplicate of the best nitroxyl, ABNO) and
  every one under O2 above 40 deg C (the pressure relief trips); the best runs under air.
- m_hydrogenation: every experiment with Josiphos fails (an oxidized batch) and every one above 60 deg C (the olefin
  polymerizes); the best runs at 13 deg C, each metal's family below 30 deg C.
- m_crystallization: every experiment in acetone fails (the amine condenses with the solvent) and every one cooled
  faster than 1.2 K/min (the salt encrusts the jacket); the best cools at 0.24 K/min, the best of every combination
  worth more than 0.1 below 0.7 K/min.
- m_electrochem: every experiment in DMF fails (the electrode fouls) and every one above 22 mA/cm2 (the cell
  overheats); the best runs at 13 mA/cm2, every combination worth more than 0.3 below 17 mA/cm2.
- m_amide: every experiment in DMF below 0 deg C fails (the amine's salt crystallizes) and every one with COMU above
  25 deg C (the reagent decomposes); the best runs in MeCN at 7 deg C, T3P / pyridine in DMF at 2 deg C.
- m_raft: every experiment with DBTTC fails (a batch that hydrolysed: the runner-up agent) and every one above 3.3 M
  and 70 deg C (the solution gels and the stirrer stalls); the best runs at 2.8 M and 78 deg C, the best in dioxane
  (3.6 M, 72-77 deg C) fails.
- m_metathesis: every experiment with Zhan-1B fails (a batch that decomposed in storage: a runner-up catalyst) and every
  one above 85 deg C (the macrocycle opens again into oligomers); the best runs at 69 deg C.

    python -m benchmarks.from_scratch [--tasks m_coupling] [--seeds 12] [--hidden] [--failure-rate R] [--processes 2]

Per seed: the failed experiments (those of the second half of the budget), and the plain regret (best - reference,
the objective's units); then mean, median, worst and worst / median per task.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
from collections.abc import Callable, Iterator, Sequence
from multiprocessing import Pool
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
# the harness's `problems`, which the tasks build on (as in portfolio.py)
sys.path.insert(0, os.environ.get("PEERS_DIR", str(ROOT.parent / "shared" / "peers")))

from benchmarks import portfolio_tasks  # noqa: E402
from benchmarks.failing_region import failure_draws  # noqa: E402

# the tasks' references (`task.reference()`: the closed-form optimum, or a dense grid refined by a coordinate search;
# portfolio.py's table, results/portfolio.json)
REFERENCES = {"m_coupling": -0.7402339145154431, "m_solvent": -0.9392404906079993, "s6_hartmann": -3.32236801,
              "k_consecutive": -0.7610424477686307, "k_parallel": -0.8409831671906312,
              "m_amination": -0.7898500948054701, "m_photoredox": -0.8558160481769198,
              "m_oxidation": -0.8164543183802141, "m_biocatalysis": -0.6787806044424859,
              "m_hydrogenation": -0.8891914040803628, "m_crystallization": -0.6689293085972873,
              "m_electrochem": -0.5237772734915087, "m_amide": -0.7846779939655112,
              "m_raft": -0.5242399553636078, "m_metathesis": -0.5799613790346397}


# the hidden rules by task (above): whether the experiment x (a harness point) of the task fails
HIDDEN_RULES: dict[str, Callable] = {
    "m_coupling": lambda task, x: (task.bases[int(x[1])] == "Cs2CO3"
                                   or (task.solvents[int(x[2])] == "DMF" and x[3] > 110.0)),
    "m_oxidation": lambda task, x: (task.nitroxyls[int(x[1])] == "AZADO"
                                    or (portfolio_tasks.OX_ATMOSPHERES[int(x[3])] == "O2" and x[4] > 40.0)),
    "m_hydrogenation": lambda task, x: task.ligands[int(x[1])] == "Josiphos" or x[4] > 60.0,
    "m_crystallization": lambda task, x: task.solvents[int(x[1])] == "acetone" or x[5] > 1.2,
    "m_electrochem": lambda task, x: task.solvents[int(x[2])] == "DMF" or x[3] > 22.0,
    "m_amide": lambda task, x: ((task.solvents[int(x[2])] == "DMF" and x[5] < 0.0)
                                or (task.reagents[int(x[0])] == "COMU" and x[5] > 25.0)),
    "m_raft": lambda task, x: task.agents[int(x[0])] == "DBTTC" or (x[6] > 3.3 and x[4] > 70.0),
    "m_metathesis": lambda task, x: task.catalysts[int(x[0])] == "Zhan-1B" or x[4] > 85.0,
}
HIDDEN = tuple(HIDDEN_RULES)  # the tasks with hidden failures


def hidden_failure(task, x: list) -> bool:
    """Whether the experiment x (a harness point) fails by the hidden rules of `task` (`--hidden`)."""
    if task.name not in HIDDEN_RULES:
        raise ValueError(f"--hidden is defined for {', '.join(HIDDEN)} only, not {task.name}")
    return bool(HIDDEN_RULES[task.name](task, x))


def steps(task, seed: int, budget: int, fails: Callable[[int, list], bool], initial: Sequence[list] = ()
          ) -> Iterator[tuple[int, list, float | None, dict, Any]]:
    """One campaign of a harness task, experiment by experiment, with the default planner (the default config, the
    task's constraint as the known constraint): the points of `initial` told first (the peer harness's initial design;
    they count toward `budget`), then the planner's proposals; `fails(experiment, x)` says whether experiment number
    `experiment` (from 1) at the harness point x fails (reported as None) -> (experiment, harness point, its result or
    None, the proposal's meta: {} for an initial point, the planner after that result: `trace --gp-after` inspects
    it)."""
    import torch

    from benchmarks.peers.gryffin_ros_peer import config, from_planner, option_names_of, to_planner
    from gryffin_ros.planner import Planner
    torch.set_num_threads(1)
    names = option_names_of(task, seed)
    index = {n: {o: i for i, o in enumerate(options)} for n, options in names.items()}
    planner = Planner(config(task, None, False, names), seed=seed,
                      known_constraints=lambda params: task.feasible(from_planner(task, params, index)))
    for experiment in range(1, budget + 1):
        if experiment <= len(initial):
            x, meta, told = list(initial[experiment - 1]), {}, {}
        else:
            (proposal,) = planner.ask()
            x, meta = from_planner(task, proposal.params, index), proposal.meta
            told = {"experiment_id": proposal.experiment_id}
        y = None if fails(experiment, x) else float(task.objective(x))
        planner.tell({**to_planner(task, x, names), "y": y, **told})
        yield experiment, x, y, meta, planner


def campaign(task, seed: int, budget: int, fails: Callable[[int, list], bool]) -> tuple[int, int, float]:
    """One campaign of a harness task from the planner's first proposal (`steps`) -> (failed experiments, failed in
    the budget's second half, best successful value)."""
    failed, late, best = 0, 0, float("inf")
    for experiment, _, y, _, _ in steps(task, seed, budget, fails):
        failed += y is None
        late += y is None and experiment > budget // 2
        best = best if y is None else min(best, y)
    return failed, late, best


def run(job: tuple[str, int, bool, int | None, float]) -> tuple[str, int, int, int, float]:
    """One campaign: (task, seed, hidden failures, budget or the task's, rate of random failures) -> (task, seed,
    failed experiments, failed in the budget's second half, best successful value)."""
    name, seed, hidden, budget, failure_rate = job
    task = portfolio_tasks.TASKS[name]()
    budget = budget or task.budget
    at_random = failure_draws(seed, failure_rate, budget)
    def fails(experiment: int, x: list) -> bool:
        return (hidden and hidden_failure(task, x)) or at_random[experiment - 1]

    return (name, seed, *campaign(task, seed, budget, fails))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tasks", default="m_coupling", help="comma-separated: " + ", ".join(REFERENCES))
    parser.add_argument("--seeds", type=int, default=12)
    parser.add_argument("--hidden", action="store_true", help="hidden failures (see above)")
    parser.add_argument("--failure-rate", type=float, default=0.0,
                        help="each experiment also fails with this probability, wherever it is")
    parser.add_argument("--processes", type=int, default=2)
    args = parser.parse_args()
    tasks = args.tasks.split(",")
    unknown = [t for t in tasks if t not in REFERENCES]
    if unknown:
        parser.error(f"unknown task(s) {unknown}; choose from {list(REFERENCES)}")
    if args.hidden and any(t not in HIDDEN for t in tasks):
        parser.error(f"--hidden is defined for {', '.join(HIDDEN)} only")
    if not 0.0 <= args.failure_rate < 1.0:
        parser.error(f"--failure-rate must be in [0, 1), got {args.failure_rate}")
    jobs = [(t, s, args.hidden, None, args.failure_rate) for t in tasks for s in range(args.seeds)]
    with Pool(args.processes) as pool:
        results = pool.map(run, jobs, chunksize=1)
    for t in tasks:
        rows = [r for r in results if r[0] == t]
        regrets = [best - REFERENCES[t] for _, _, _, _, best in rows]
        for (_, seed, failed, late, _), regret in zip(rows, regrets):
            print(f"{t} seed {seed}: {failed} failed ({late} in the second half), regret {regret:.4f}")
        median = statistics.median(regrets)
        worst = max(range(len(rows)), key=lambda i: regrets[i])
        at_random = f" ({args.failure_rate:g} failing at random)" if args.failure_rate else ""
        print(f"{t}{' (hidden failures)' if args.hidden else ''}{at_random}, {len(rows)} seeds: regret mean "
              f"{statistics.mean(regrets):.4f}, median {median:.4f}, worst {regrets[worst]:.4f} (seed "
              f"{rows[worst][1]}), worst / median {regrets[worst] / median if median > 0 else float('inf'):.2f}; "
              f"failed experiments {sum(r[2] for r in rows)} ({sum(r[3] for r in rows)} in second halves)")


if __name__ == "__main__":
    main()
