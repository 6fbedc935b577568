"""Lab-scale ask times of the default planner (issue #20, item 3), one thread, on a constrained smooth problem:

- warm asks around n = 1000 observations, d = 10 (the median of 10 consecutive asks, n = 996 ... 1005, and the
  slowest of them), and the first ask of a fresh planner on 995 observations; `warm_free`: the same without the known
  constraints (the constrained optimum lies on the linear one, where Adam's steps are projected back onto it, and
  the nonlinear one would stop them; without constraints every step is taken as it is);
- a batch of 8 at n = 200, d = 6;
- a batch of 96 (a well plate) at n = 500, d = 6, and how spread out it is: the smallest pairwise distance of its
  points (unit cube) against that of 96 random feasible points (median over 20 draws);
- a Gryffin 1.0 script's loop: stateless `recommend` on a list that grows by one, n = 100 ... 119, d = 2, on one
  planner (it reuses the fits of the same first observations) and on a fresh planner per call (nothing to reuse);
- asks on issue #37's mixed Suzuki-like space (3 catalysts, 4 solvents with descriptors, 3 continuous conditions,
  T below the solvent's boiling point, Chimera yield then cost) at n = 5, 16, 50, 100 (median of 5 warm asks).

    .venv/bin/python -m benchmarks.lab_scale [--surrogate NAME] [--repeats 3] [--cases warm,...,mixed]
                                             [--out benchmarks/results/lab_scale.md]

Observations are random feasible points with their objective values, told in one call; "warm" = the planner has
answered the previous ask and is told its result (what a running campaign does).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

import numpy as np
import torch

from gryffin_ros.planner import Planner

WARM_ASKS = 10
# issue #37's Suzuki-like campaign: 3 catalysts, 4 solvents with descriptors, 3 continuous conditions, a constraint
# on a solvent's boiling point, Chimera yield then cost
MIXED_SIZES, MIXED_ASKS = (5, 16, 50, 100), 5
SOLVENTS = {"THF": [66.0, 7.5], "dioxane": [101.0, 2.2], "toluene": [111.0, 2.4], "DMF": [153.0, 36.7]}
MIXED = {
    "parameters": [{"name": "catalyst", "type": "categorical", "options": ["Pd(PPh3)4", "Pd(dppf)Cl2", "XPhos Pd G3"]},
                   {"name": "solvent", "type": "categorical", "options": list(SOLVENTS),
                    "descriptors": SOLVENTS, "descriptor_names": ["boiling_point", "dielectric"]},
                   {"name": "T", "type": "continuous", "low": 40.0, "high": 150.0},
                   {"name": "t", "type": "continuous", "low": 0.5, "high": 24.0},
                   {"name": "loading", "type": "continuous", "low": 0.5, "high": 5.0}],
    "objectives": [{"name": "yield", "goal": "max", "tolerance": 0.2, "absolute": False},
                   {"name": "cost", "goal": "min"}],
    "constraints": ["T < boiling_point(solvent) - 5"],
}


def problem(d: int, surrogate: str | None, constrained: bool = True) -> dict:
    names = [f"x{i}" for i in range(d)]
    general = {"surrogate": surrogate} if surrogate else {}
    constraints = [" + ".join(names) + f" <= {0.6 * d}",
                   " + ".join(f"(x{i} - 0.5)**2" for i in range(d)) + " >= 0.04"]
    return {"parameters": [{"name": n, "type": "continuous", "low": 0.0, "high": 1.0} for n in names],
            "objectives": [{"name": "y", "goal": "min"}], "general": general,
            "constraints": constraints if constrained else []}


def objective(x: np.ndarray) -> float:
    return float(np.sum(np.sin(5 * x) + (x - 0.3) ** 2))


def feasible_points(m: int, d: int, rng: np.random.Generator, constrained: bool = True) -> np.ndarray:
    if not constrained:
        return rng.random((m, d))
    out = []
    while len(out) < m:
        x = rng.random((4 * m, d))
        keep = (x.sum(1) <= 0.6 * d) & (((x - 0.5) ** 2).sum(1) >= 0.04)
        out.extend(x[keep])
    return np.array(out[:m])


def planner_with(n: int, d: int, surrogate: str | None, seed: int, constrained: bool = True
                 ) -> tuple[Planner, np.random.Generator]:
    rng = np.random.default_rng(seed)
    planner = Planner(problem(d, surrogate, constrained), seed=seed)
    X = feasible_points(n, d, rng, constrained)
    planner.tell([{"params": {f"x{i}": float(v) for i, v in enumerate(x)}, "objectives": {"y": objective(x)}}
                  for x in X])
    return planner, rng


def timed_ask(planner: Planner, count: int) -> tuple[float, list]:
    start = time.process_time()
    proposals = planner.ask(count)
    return time.process_time() - start, proposals


def tell_result(planner: Planner, proposal) -> None:
    x = np.array([proposal.params[f"x{i}"] for i in range(len(proposal.params))])
    planner.tell({"experiment_id": proposal.experiment_id, "params": proposal.params,
                  "objectives": {"y": objective(x)}})


def mixed_result(p: dict) -> dict:
    """A smooth synthetic yield with a best catalyst-solvent pair, and a cost of catalyst loading and time."""
    cat = ["Pd(PPh3)4", "Pd(dppf)Cl2", "XPhos Pd G3"].index(p["catalyst"])
    sol = list(SOLVENTS).index(p["solvent"])
    y = (0.4 + 0.2 * cat + 0.1 * sol) * np.exp(-((p["T"] - 95.0) / 40.0) ** 2) * (1 - np.exp(-p["t"] / 4.0))
    cost = p["loading"] * (1 + 0.2 * cat) + 0.1 * p["t"]
    return {"yield": float(y * min(1.0, p["loading"] / 2.0)), "cost": float(cost)}


def mixed_planner(n: int, surrogate: str | None, seed: int) -> Planner:
    config = dict(MIXED, general={"surrogate": surrogate} if surrogate else {})
    planner = Planner(config, seed=seed)
    rng = np.random.default_rng(seed)
    rows = []
    while len(rows) < n:
        p = {"catalyst": str(rng.choice(MIXED["parameters"][0]["options"])), "solvent": str(rng.choice(list(SOLVENTS))),
             "T": float(rng.uniform(40, 150)), "t": float(rng.uniform(0.5, 24)), "loading": float(rng.uniform(0.5, 5))}
        if p["T"] < SOLVENTS[p["solvent"]][0] - 5:
            rows.append({"params": p, "objectives": mixed_result(p)})
    planner.tell(rows)
    return planner


def min_distance(points: np.ndarray) -> float:
    diff = points[:, None, :] - points[None, :, :]
    dist = np.sqrt((diff ** 2).sum(-1))
    return float(dist[np.triu_indices(len(points), 1)].min())


def case_warm(a, rows: list, notes: list, constrained: bool = True) -> None:
    first, warm, slowest, meta = [], [], [], []
    label = "" if constrained else ", no known constraints"
    for seed in range(a.repeats):
        planner, _ = planner_with(995, 10, a.surrogate, seed, constrained)
        t, proposals = timed_ask(planner, 1)
        first.append(t)
        times = []
        for _ in range(WARM_ASKS):  # n = 996 ... 1005: a campaign's asks, one of them refits the hyperparameters
            tell_result(planner, proposals[0])
            t, proposals = timed_ask(planner, 1)
            times.append(t)
        warm.append(statistics.median(times))
        slowest.append(max(times))
        meta.append(proposals[0].meta)
        print(f"n=1000 d=10{label} seed {seed}: first {first[-1]:.2f} s, warm median {warm[-1]:.2f} s, slowest "
              f"{slowest[-1]:.2f} s, meta {meta[-1]}", flush=True)
    rows.append((f"warm ask, n = 996–1005, d = 10{label} (median of {WARM_ASKS} asks)", "≤ 0.8 s",
                 statistics.median(warm)))
    rows.append(("slowest of those (the one that refits the hyperparameters)", "—", statistics.median(slowest)))
    rows.append((f"first ask, n = 995, d = 10{label}", "≤ 5 s", statistics.median(first)))
    notes.append(f"Proposal meta at n = 1000{label}: " + "; ".join(str(m) for m in meta))


def case_warm_free(a, rows: list, notes: list) -> None:
    case_warm(a, rows, notes, constrained=False)


def case_batch8(a, rows: list, notes: list) -> None:
    batch8 = []
    for seed in range(a.repeats):
        planner, _ = planner_with(200, 6, a.surrogate, seed)
        planner.ask(1)  # warm: the fit of this campaign exists
        t, _ = timed_ask(planner, 8)
        batch8.append(t)
        print(f"batch of 8, n=200 d=6 seed {seed}: {t:.2f} s", flush=True)
    rows.append(("batch of 8, n = 200, d = 6", "≤ 1.5 s", statistics.median(batch8)))


def case_batch96(a, rows: list, notes: list) -> None:
    batch96, spread = [], []
    for seed in range(a.repeats):
        planner, rng = planner_with(500, 6, a.surrogate, seed)
        planner.ask(1)
        t, proposals = timed_ask(planner, 96)
        batch96.append(t)
        points = np.array([[p.params[f"x{i}"] for i in range(6)] for p in proposals])
        random_spread = statistics.median(min_distance(feasible_points(96, 6, rng)) for _ in range(20))
        spread.append((min_distance(points), random_spread))
        print(f"batch of 96, n=500 d=6 seed {seed}: {t:.2f} s, min distance {spread[-1][0]:.3f} "
              f"(random feasible {random_spread:.3f})", flush=True)
    rows.append(("batch of 96, n = 500, d = 6", "≤ 15 s", statistics.median(batch96)))
    notes.append("Batch of 96: smallest pairwise distance of the proposals (unit cube) vs 96 random feasible points "
                 "(median of 20 draws): " + "; ".join(f"{ours:.3f} vs {rand:.3f}" for ours, rand in spread))


def case_stateless(a, rows: list, notes: list) -> None:
    loop, fresh = [], []
    for seed in range(a.repeats):
        rng = np.random.default_rng(seed)
        X = feasible_points(120, 2, rng)
        rows_2d = [{"x0": float(x[0]), "x1": float(x[1]), "y": objective(x)} for x in X]
        planner = Planner(problem(2, a.surrogate), seed=seed)
        planner.recommend(rows_2d[:99])
        times = []
        for n in range(100, 120):
            start = time.process_time()
            planner.recommend(rows_2d[:n])
            times.append(time.process_time() - start)
        loop.append((statistics.median(times), statistics.mean(times)))
        start = time.process_time()
        Planner(problem(2, a.surrogate), seed=seed).recommend(rows_2d[:100])
        fresh.append(time.process_time() - start)
        print(f"stateless recommend n=100..119 d=2 seed {seed}: median {loop[-1][0]:.3f} s, mean {loop[-1][1]:.3f} "
              f"s; fresh planner at n=100 {fresh[-1]:.3f} s", flush=True)
    rows.append(("stateless recommend, n = 100–119, d = 2, one planner (median of the 20 calls)", "≤ 0.12 s",
                 statistics.median(m for m, _ in loop)))
    rows.append(("the same, mean of the 20 calls (every 10th refits)", "—", statistics.median(m for _, m in loop)))
    rows.append(("stateless recommend on a fresh planner, n = 100, d = 2 (fit and feasible-region estimate anew)",
                 "—", statistics.median(fresh)))


def case_mixed(a, rows: list, notes: list) -> None:
    for n in MIXED_SIZES:
        medians = []
        for seed in range(a.repeats):
            planner = mixed_planner(n, a.surrogate, seed)
            planner.ask(1)  # warm: this campaign's fit exists
            times = []
            for _ in range(MIXED_ASKS):
                t, (proposal,) = timed_ask(planner, 1)
                times.append(t)
                planner.tell({"experiment_id": proposal.experiment_id, "params": proposal.params,
                              "objectives": mixed_result(proposal.params)})
            medians.append(statistics.median(times))
            print(f"mixed n={n} seed {seed}: median {medians[-1]:.2f} s ({proposal.meta.get('surrogate')})",
                  flush=True)
        rows.append((f"mixed Suzuki-like space, n = {n} (median of {MIXED_ASKS} warm asks)", "≤ 1 s",
                     statistics.median(medians)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--surrogate", default=None, help="general.surrogate (default: the planner's default)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=None)
    ap.add_argument("--cases", default="warm,warm_free,batch8,batch96,stateless,mixed",
                    help="comma-separated: warm, warm_free, batch8, batch96, stateless, mixed")
    a = ap.parse_args()
    torch.set_num_threads(1)
    label = a.surrogate or "default"

    cases = {"warm": case_warm, "warm_free": case_warm_free, "batch8": case_batch8, "batch96": case_batch96,
             "stateless": case_stateless, "mixed": case_mixed}
    rows: list = []
    notes: list = []
    for name in a.cases.split(","):
        if name not in cases:
            raise SystemExit(f"unknown case {name!r}; cases are {sorted(cases)}")
        cases[name](a, rows, notes)

    lines = [f"Lab-scale ask CPU time, surrogate {label} (median of {a.repeats}; one thread; "
             f"{os.cpu_count()} cores here)", "", "| case | target | CPU s |", "|---|---|---|"]
    lines += [f"| {case} | {target} | {value:.2f} |" for case, target, value in rows]
    lines += [line for note in notes for line in ("", note)]
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        Path(a.out).write_text(text)


if __name__ == "__main__":
    main()
