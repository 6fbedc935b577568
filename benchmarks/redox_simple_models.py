"""Simple models outside Gryffin on the redox campaign, as a yardstick for the kernel density: experiments until the
best synthesizable candidate (R1_0, R3_7, R4_7, R5_0) is measured, choosing each next candidate among the 959
synthesizable ones by

- `blr-merit`: Bayesian linear regression on one-hot R-groups (main effects only) of the sqrt Chimera merit,
  Thompson sampling;
- `blr-objectives`: the same model for each objective, Chimera over the observed values and the drawn predictions;
- `gp-<kernel>-<acquisition>`: a GP of the standardized sqrt merit with a kernel over the four R-groups: `add` (sum
  of per-group kernels), `prod` (their product) or `both` (sum of the two); per-group kernels on the options
  (1 for the same option, e^-1/l otherwise, l = 0.3) or, with `desc`, a squared-exponential on the mordred
  descriptors (columns scaled to [0, 1], l = 0.15); acquisition expected improvement (`ei`), lower confidence bound
  mu - 2 sigma (`lcb`) or independent Thompson draws (`ts`).

One random first candidate per seed, the DFT values of the example without noise, up to 100 experiments.

    python -m benchmarks.redox_simple_models [--seeds 40] [--out benchmarks/results/redox_simple_models.md]
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np
import torch

from gryffin_ros.emulators import RedoxEmulator
from gryffin_ros.paths import share_path
from gryffin_ros.planner.chimera import Chimera
from gryffin_ros.planner.config import load_config

BUDGET = 100
BEST = ("R1_0", "R3_7", "R4_7", "R5_0")
NOISE = 0.1  # noise variance of the linear model, standardized units
JITTER = 1e-3  # the GP's noise variance, standardized units
GP_MODELS = [f"gp-{k}-{a}" for k in ("add", "prod", "both") for a in ("ei", "lcb", "ts")] + \
    [f"gp-desc-{k}-{a}" for k in ("add", "both") for a in ("ei", "lcb")]


class Problem:
    def __init__(self):
        config = load_config(share_path("examples") / "redox_flow_battery.yaml", share_path("examples"))
        self.chimera = Chimera(config.objectives, config.general.softness)
        names = [p.name for p in config.space.parameters]
        with open(share_path("examples") / "redox_feasible_959.csv") as handle:
            self.candidates = [tuple(row[n] for n in names) for row in csv.DictReader(handle)]
        emulator = RedoxEmulator()
        measured = [emulator.measure(dict(zip(names, c))) for c in self.candidates]
        self.Y = np.array([[m[o.name] for o in config.objectives] for m in measured])
        self.best = self.candidates.index(BEST)
        options = [p.options for p in config.space.parameters]
        self.index = np.array([[options[j].index(c[j]) for j in range(len(names))] for c in self.candidates])
        self.onehot = np.column_stack([np.ones(len(self.candidates))] + [
            (self.index[:, j] == k).astype(float) for j in range(len(names)) for k in range(len(options[j]))])
        same = [(self.index[:, None, j] == self.index[None, :, j]).astype(float) for j in range(len(names))]
        self.option_kernels = [s + (1 - s) * np.exp(-1 / 0.3) for s in same]
        self.descriptor_kernels = []
        for j in range(len(names)):
            table = config.space.descriptors(config.space.finite_idx[j])
            span = np.ptp(table, axis=0)
            table = (table - table.min(0)) / np.where(span > 0, span, 1.0)
            d = table[self.index[:, j]]
            sq = ((d[:, None] - d[None]) ** 2).mean(-1)
            self.descriptor_kernels.append(np.exp(-0.5 * sq / 0.15 ** 2))

    def merits(self, Y: np.ndarray) -> np.ndarray:
        return np.sqrt(self.chimera.merits(Y))


def blr_draw(problem: Problem, observed: list[int], y: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A posterior draw of the main-effects model of y at every candidate (prior N(0, 1) on standardized y)."""
    scale = y.std() + 1e-9
    t = (y - y.mean()) / scale
    A = problem.onehot[observed]
    L = np.linalg.cholesky(np.eye(A.shape[1]) + A.T @ A / NOISE)  # posterior precision L L^T
    mean = np.linalg.solve(L.T, np.linalg.solve(L, A.T @ t / NOISE))
    w = mean + np.linalg.solve(L.T, rng.standard_normal(A.shape[1]))
    return problem.onehot @ w * scale + y.mean()


def gp_score(K: np.ndarray, observed: list[int], y: np.ndarray, acquisition: str, rng: np.random.Generator
             ) -> np.ndarray:
    t = (y - y.mean()) / (y.std() + 1e-9)
    L = np.linalg.cholesky(K[np.ix_(observed, observed)] + JITTER * np.eye(len(observed)))
    Kc = K[:, observed]
    mu = Kc @ np.linalg.solve(L.T, np.linalg.solve(L, t))
    v = np.linalg.solve(L, Kc.T)
    sigma = np.sqrt(np.clip(np.diag(K) - (v * v).sum(0), 1e-12, None))
    if acquisition == "lcb":
        return mu - 2 * sigma
    if acquisition == "ts":
        return mu + sigma * rng.standard_normal(len(mu))
    z = (t.min() - mu) / sigma
    cdf = torch.special.ndtr(torch.as_tensor(z)).numpy()
    return -sigma * (z * cdf + np.exp(-0.5 * z ** 2) / np.sqrt(2 * np.pi))


def kernel(problem: Problem, model: str) -> np.ndarray:
    parts = model.split("-")
    kernels = problem.descriptor_kernels if parts[1] == "desc" else problem.option_kernels
    kind = parts[-2]
    add, prod = sum(kernels) / len(kernels), np.prod(kernels, axis=0)
    return {"add": add, "prod": prod, "both": add + prod}[kind]


def run(problem: Problem, model: str, seed: int, K: np.ndarray | None) -> int | None:
    rng = np.random.default_rng(seed)
    observed = [int(rng.integers(len(problem.candidates)))]
    while observed[-1] != problem.best and len(observed) < BUDGET:
        Y = problem.Y[observed]
        if model == "blr-merit":
            score = blr_draw(problem, observed, problem.merits(Y), rng)
        elif model == "blr-objectives":
            draws = np.column_stack([blr_draw(problem, observed, Y[:, j], rng) for j in range(Y.shape[1])])
            score = problem.merits(np.concatenate([Y, draws]))[len(observed):]
        else:
            score = gp_score(K, observed, problem.merits(Y), model.split("-")[-1], rng)
        score[observed] = np.inf
        observed.append(int(np.argmin(score)))
    return len(observed) if observed[-1] == problem.best else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=40)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "redox_simple_models.md")
    args = parser.parse_args()
    problem = Problem()
    lines = [f"Redox candidates, simple models ({args.seeds} seeds, {BUDGET} experiments): runs that measured the best "
             "candidate, median and mean experiments to it (not found counted as 100).", "",
             "| model | found | median | mean |", "|---|---|---|---|"]
    for model in ["blr-merit", "blr-objectives"] + GP_MODELS:
        K = kernel(problem, model) if model.startswith("gp") else None
        found = [run(problem, model, seed, K) for seed in range(args.seeds)]
        steps = [f if f is not None else BUDGET for f in found]
        median = np.median([f if f is not None else np.inf for f in found])
        lines.append(f"| {model} | {np.mean([f is not None for f in found]):.0%} | "
                     f"{'> 100' if np.isinf(median) else f'{median:g}'} | {np.mean(steps):.1f} |")
        print(lines[-1], flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
