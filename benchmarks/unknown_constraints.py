"""The paper's discrete surfaces with their constraints NOT given to the planner: an infeasible evaluation returns
NaN (a failed experiment) and counts toward the budget. Reports evaluations until the optimum is evaluated, with the
1-d ordinal descriptor (discrete parameters) and without descriptors (categorical options).

    python -m benchmarks.unknown_constraints [--seeds 100] [--processes 2] [--out benchmarks/results]
                                             [--concrete-temperature C] [--surrogate kde|gp|auto|portfolio]
                                             [--feas-model kde|gp] [--variants ordinal naive]
                                             [--surfaces slope sphere michalewicz camel]

Per-run results are kept in <out>/unknown_constraints_runs.json, so an interrupted run resumes.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
from multiprocessing import Pool
from pathlib import Path

from benchmarks.surfaces import DISCRETE_SURFACES, OPTIONS

# Atlas (GP with a feasibility classifier), best setting, recomputed from its raw results (issue text).
ANCHOR = {"slope": 15.2, "sphere": 14.7, "michalewicz": 23.4, "camel": 48.6}


def config(variant: str, temperature: float | None = None, surrogate: str | None = None,
           feas_model: str | None = None) -> dict:
    if variant == "ordinal":
        parameters = [{"name": n, "type": "discrete", "low": 0, "high": OPTIONS - 1} for n in ("x0", "x1")]
    else:
        parameters = [{"name": n, "type": "categorical", "options": [f"x_{i}" for i in range(OPTIONS)]}
                      for n in ("x0", "x1")]
    out = {"parameters": parameters, "objectives": [{"name": "y", "goal": "min"}]}
    general = {"concrete_temperature": temperature} if temperature is not None else {}
    if surrogate is not None:
        general["surrogate"] = surrogate
    if feas_model is not None:
        general["feas_model"] = feas_model
    if general:
        out["general"] = general
    return out


def run(job: tuple[str, str, int, float | None, str | None, str | None]) -> tuple[str, str, int, int, int]:
    """-> (surface, variant, seed, evaluations until the optimum, failed evaluations)."""
    import torch

    from gryffin_ros.planner import Planner
    torch.set_num_threads(1)
    surface_name, variant, seed, temperature, surrogate, feas_model = job
    surface = DISCRETE_SURFACES[surface_name]
    optimum = surface.optimum()
    planner = Planner(config(variant, temperature, surrogate, feas_model), seed=seed)
    failed = 0
    for evaluation in range(1, OPTIONS * OPTIONS + 1):
        (proposal,) = planner.ask()
        cell = tuple(int(str(proposal.params[n]).removeprefix("x_")) for n in ("x0", "x1"))
        value = surface.objective(*cell) if surface.feasible(*cell) else None
        failed += value is None
        planner.tell({**proposal.params, "y": value, "experiment_id": proposal.experiment_id})
        if cell == optimum:
            return surface_name, variant, seed, evaluation, failed
    return surface_name, variant, seed, OPTIONS * OPTIONS, failed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--processes", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--concrete-temperature", type=float, default=None,
                        help="general.concrete_temperature (default: the planner's); results go to files of their own")
    parser.add_argument("--surrogate", default=None,
                        help="general.surrogate (default: the planner's); results go to files of their own")
    parser.add_argument("--feas-model", default=None,
                        help="general.feas_model (default: the planner's); results go to files of their own")
    parser.add_argument("--variants", nargs="+", default=["ordinal", "naive"], choices=["ordinal", "naive"],
                        help="ordinal descriptor, no descriptor (default: both)")
    parser.add_argument("--surfaces", nargs="+", default=list(DISCRETE_SURFACES), choices=list(DISCRETE_SURFACES))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    suffix = "" if args.concrete_temperature is None else f"_c{args.concrete_temperature:g}"
    suffix += "" if args.surrogate is None else f"_{args.surrogate}"
    suffix += "" if args.feas_model is None else f"_feas-{args.feas_model}"
    store = args.out / f"unknown_constraints_runs{suffix}.json"
    done = {tuple(r[:3]): r for r in (json.loads(store.read_text()) if store.exists() else [])}
    jobs = [(s, v, seed, args.concrete_temperature, args.surrogate, args.feas_model) for s in args.surfaces
            for v in args.variants
            for seed in range(args.seeds) if (s, v, seed) not in done]
    with Pool(args.processes) as pool:
        for result in (pool.imap_unordered(run, jobs) if args.processes > 1 else map(run, jobs)):
            done[tuple(result[:3])] = list(result)
            store.write_text(json.dumps(sorted(done.values())))
    rows = ["| surface | ordinal descriptor: mean ± s.e. (median) | no descriptor: mean ± s.e. (median) | "
            "failed evaluations (ordinal, mean) | Atlas anchor |", "|---|---|---|---|---|"]
    for surface in args.surfaces:
        cells = []
        for variant in ("ordinal", "naive"):
            evals = [r[3] for r in done.values() if r[0] == surface and r[1] == variant and r[2] < args.seeds]
            if not evals:
                cells.append("not run")
                continue
            se = statistics.stdev(evals) / math.sqrt(len(evals)) if len(evals) > 1 else float("nan")
            cells.append(f"{statistics.mean(evals):.1f} ± {se:.1f} ({statistics.median(evals):g})")
        failed = [r[4] for r in done.values() if r[0] == surface and r[1] == "ordinal" and r[2] < args.seeds]
        failed_mean = f"{statistics.mean(failed):.1f}" if failed else "not run"
        rows.append(f"| {surface} | {cells[0]} | {cells[1]} | {failed_mean} | {ANCHOR[surface]} |")
    text = f"Evaluations to the optimum, constraints unknown to the planner, {args.seeds} seeds:\n\n" + "\n".join(rows)
    (args.out / f"unknown_constraints{suffix}.md").write_text(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
