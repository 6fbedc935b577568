"""The benchmark runner behind `benchmarks/bench.py`: the paper's protocol on the paper's surfaces, in parallel over
seeds and resumable.

Protocol (paper, SI): one proposal per ask, the planner's two sampling strategies (lambda = -1, +1) alternating;
continuous surfaces run a fixed budget and report the best-so-far objective; discrete surfaces stop when the
constrained optimum is evaluated and report how many evaluations that took. Every proposal is checked against the
surface's constraint (a violation ends that run and is counted; the target is zero).

Each run is written to ``<out>/<surface>/<strategy>[-<variant>]/budget<B>/seed<NNNN>.json`` as soon as it ends, and
runs already on disk are not repeated, so an interrupted benchmark resumes where it stopped.
"""

from __future__ import annotations

import json
import math
import os
import statistics
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path
from typing import Any

from benchmarks.surfaces import SURFACES, ContinuousSurface, DiscreteSurface
from gryffin_ros.planner import Genetic, GryffinRosError, Planner, Random
from gryffin_ros.planner.strategies import BasePlanner

# adam/genetic: the kernel density (the paper's model) under either acquisition optimizer; gp/auto/portfolio:
# general.surrogate gp/auto/portfolio with Adam; default: the planner's defaults (no general section)
STRATEGIES = ("adam", "genetic", "gp", "auto", "portfolio", "default", "random", "deap")
TRACE_POINTS = (10, 20, 50, 100)


@dataclass(frozen=True)
class Job:
    surface: str
    strategy: str
    seed: int
    budget: int
    variant: str | None = None  # discrete surfaces: "ordinal" (default) or "categorical"

    @property
    def label(self) -> str:
        return self.strategy if self.variant in (None, "ordinal", "continuous") else f"{self.strategy}-{self.variant}"

    def path(self, out: Path) -> Path:
        return Path(out) / self.surface / self.label / f"budget{self.budget}" / f"seed{self.seed:04d}.json"


def make_planner(surface: DiscreteSurface | ContinuousSurface, strategy: str, seed: int,
                 variant: str | None = None) -> BasePlanner:
    """The strategy's planner on the surface's search space, with the surface's constraint as a known constraint."""
    if strategy not in STRATEGIES:
        raise ValueError(f"unknown strategy {strategy!r}; choose from {', '.join(STRATEGIES)}")
    config = surface.config(variant) if variant else surface.config()
    if strategy in ("adam", "genetic"):
        config["general"] = {"acquisition_optimizer": strategy, "surrogate": "kde"}
        return Planner(config, known_constraints=surface.constraint, seed=seed)
    if strategy in ("gp", "auto", "portfolio", "default"):
        if strategy != "default":
            config["general"] = {"surrogate": strategy}
        return Planner(config, known_constraints=surface.constraint, seed=seed)
    cls = Random if strategy == "random" else Genetic
    return cls(config, known_constraints=surface.constraint, seed=seed)


def run_job(job: Job) -> dict[str, Any]:
    """One optimization run -> its record (values, points, violations, evaluations to the optimum, seconds)."""
    import torch  # one thread per run: the runs themselves are spread over the cores
    torch.set_num_threads(1)
    surface = SURFACES[job.surface]
    planner = make_planner(surface, job.strategy, job.seed, job.variant)
    values: list[float] = []
    points: list[list[Any]] = []
    violations, found, error, ask_seconds = 0, None, None, []
    start = time.perf_counter()
    for evaluation in range(1, job.budget + 1):
        tick = time.perf_counter()
        try:
            (proposal,) = planner.ask()
        except GryffinRosError as exc:  # e.g. a finite space exhausted: the run ends and says why
            error = f"{type(exc).__name__}: {exc}"
            break
        ask_seconds.append(time.perf_counter() - tick)
        params = proposal.params
        points.append([params["x0"], params["x1"]])
        if not surface.is_feasible(params):
            violations += 1
            break
        value = surface.evaluate(params)
        values.append(value)
        planner.tell({**params, "y": value, "experiment_id": proposal.experiment_id})
        if surface.kind == "discrete" and surface.is_optimum(params):
            found = evaluation
            break
    return {
        "surface": job.surface, "strategy": job.strategy, "variant": job.variant, "seed": job.seed,
        "budget": job.budget, "values": values, "points": points, "violations": violations,
        "evaluations_to_optimum": found, "error": error, "seconds": time.perf_counter() - start,
        "median_ask_seconds": statistics.median(ask_seconds) if ask_seconds else None,
    }


def _write(path: Path, record: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(record))
    os.replace(tmp, path)


def run_jobs(jobs: Sequence[Job], out: Path, processes: int | None = None,
             progress: Callable[[Job, dict[str, Any]], None] | None = None) -> list[dict[str, Any]]:
    """Run the jobs not yet on disk (in parallel), store each as it ends; return the records of all jobs."""
    todo = [job for job in jobs if not job.path(out).exists()]
    processes = max(1, min(processes or os.cpu_count() or 1, len(todo) or 1))
    if todo:
        if processes == 1:
            for job in todo:
                record = run_job(job)
                _write(job.path(out), record)
                if progress:
                    progress(job, record)
        else:
            with get_context("spawn").Pool(processes) as pool:
                for job, record in zip(todo, pool.imap(run_job, todo)):
                    _write(job.path(out), record)
                    if progress:
                        progress(job, record)
    return [json.loads(job.path(out).read_text()) for job in jobs]


def load_records(out: Path, surface: str, label: str, budget: int) -> list[dict[str, Any]]:
    folder = Path(out) / surface / label / f"budget{budget}"
    return [json.loads(p.read_text()) for p in sorted(folder.glob("seed*.json"))]


def best_so_far(values: Sequence[float], budget: int) -> list[float]:
    """Running minimum, padded to `budget` with the last value (a discrete run stops at the optimum)."""
    trace, best = [], math.inf
    for v in values:
        best = min(best, v)
        trace.append(best)
    return trace + [best] * (budget - len(trace))


def _mean_se(xs: Sequence[float]) -> tuple[float, float]:
    mean = statistics.fmean(xs)
    se = statistics.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else 0.0
    return mean, se


def summarize(records: Iterable[dict[str, Any]]) -> dict[str, Any]:
    """Mean, s.e. and median of evaluations to the optimum (discrete), best-so-far and regret at 10/20/50/100
    (continuous and discrete), constraint violations, median ask time."""
    records = list(records)
    if not records:
        return {"runs": 0}
    surface = SURFACES[records[0]["surface"]]
    budget = records[0]["budget"]
    out: dict[str, Any] = {"runs": len(records), "violations": sum(r["violations"] for r in records),
                           "errors": sum(r.get("error") is not None for r in records)}
    asks = [r["median_ask_seconds"] for r in records if r.get("median_ask_seconds") is not None]
    out["median_ask_seconds"] = statistics.median(asks) if asks else None
    if surface.kind == "discrete":
        # a run that never found the optimum counts with its budget (a lower bound), as in the paper's tables
        evals = [r["evaluations_to_optimum"] or budget for r in records]
        out["found"] = sum(r["evaluations_to_optimum"] is not None for r in records)
        out["evaluations_mean"], out["evaluations_se"] = _mean_se(evals)
        out["evaluations_median"] = statistics.median(evals)
    optimum = surface.optimum_value
    traces = [best_so_far(r["values"], budget) for r in records if r["values"]]
    for k in TRACE_POINTS:
        if k <= budget and traces:
            mean, se = _mean_se([t[k - 1] for t in traces])
            out[f"best_at_{k}"] = mean
            out[f"best_at_{k}_se"] = se
            out[f"regret_at_{k}"] = mean - optimum
    return out


def format_summary(surface: str, label: str, summary: dict[str, Any]) -> str:
    if not summary.get("runs"):
        return f"{surface:18s} {label:22s} no runs"
    parts = [f"{surface:18s} {label:22s} runs {summary['runs']:4d}  violations {summary['violations']}"]
    if "evaluations_mean" in summary:
        parts.append(f"evaluations to optimum {summary['evaluations_mean']:.1f} +- {summary['evaluations_se']:.1f} "
                     f"(median {summary['evaluations_median']:g}, found {summary['found']}/{summary['runs']})")
    else:
        traces = "  ".join(f"@{k} {summary[f'best_at_{k}']:.4g}" for k in TRACE_POINTS if f"best_at_{k}" in summary)
        parts.append(f"best-so-far {traces}")
    if summary.get("median_ask_seconds") is not None:
        parts.append(f"median ask {summary['median_ask_seconds'] * 1000:.0f} ms")
    return "  ".join(parts)
