"""Unknown constraints learned from failed experiments: P(feasible | x) from the kernel densities of successful and
failed observations, and its combination with the acquisition (fwt, fwa, fia, fca).

Two kernel estimates, each P = (sum_{k ok} p_k(x) + prior * u) / (sum_k p_k(x) + u), u = c/V the uniform density
acting as c prior pseudo-observations. The wide one (kernels as broad as the spacing of the data, descriptors shared
between options) has the constant prior pi = (n_ok + 1) / (n + 2) and c = WIDE_PRIOR_WEIGHT; the narrow one
(Gryffin's kernels, each option on its own, c = 1) has the wide estimate as its prior. Near observations the narrow
kernels decide, between them the wide ones extend what was seen, far from everything P = pi. Each estimate is 1 -
alpha of the kernel acquisition with the failure labels as merits, so the same numerics (log space, no underflow)
serve both. With general.feas_model = gp a GP classifier of feasibility (`surrogates.gp_classifier`, Atlas' model)
takes the wide estimate's place as the narrow kernels' prior. An option of a small categorical parameter that fails more
often than the campaign's experiments do lowers P wherever it is set (`option_factors`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

import numpy as np
import torch

from ..space import SearchSpace
from ..surrogates.kernel_density import KernelDensity
from .kernel import Acquisition

APPROACHES = ("fwt", "fwa", "fia", "fca")
FCA_MIN_PASSING = 0.1
# fwt (the default): fwa with P(feasible) counted as 1 from this value up. fwa's product let a good candidate beside a
# few failures (P ~ 0.6: the failure model's kernels are as wide as the data's spacing) lose to poorer ones far from
# them; fca's hard cut (P > 0.5 only) kept a cell whose options all failed elsewhere out until almost every other one
# was tried (Michalewicz without descriptors: 2 of 30 seeds at 440 of 441). benchmarks/README.md, round four.
FWT_THRESHOLD = 0.5
# The wide estimate's prior counts as this many observations spread over the space (Gryffin's kernel acquisition: one).
# With one, a few failures early in a campaign (random ones too: a blocked line, a cracked vial) lowered the wide P
# across their part of the space, fwt's weight to the power 5 on the GP's EI kept the campaign out of it, and one that
# had found a local basin elsewhere never went back: the six-hump camel with 30 % of experiments failing at random,
# 4 of 96 campaigns ended on a local minimum (with P taken as 1, those four ended within 0.05 of the optimum); 0 of 96
# with three, the failing regions and the paper's surfaces with unknown constraints within noise
# (benchmarks/README.md, round twelve).
WIDE_PRIOR_WEIGHT = 3.0
# An option that fails more often than the campaign's experiments do, whatever the rest of the point: P(feasible) is
# scaled by min(1, r_o / pi) for each option o of a categorical parameter with 2 to OPTION_MAX_OPTIONS options, r_o its
# success rate with pi as a prior worth OPTION_PRIOR_WEIGHT experiments, (successes + w pi) / (runs + w). The kernels
# are local in every coordinate at once: after a base had failed in all of its 4 to 6 runs, a point with that base
# beside successes with other bases still got P 0.99 - 1.00 (m_coupling from scratch, Cs2CO3 failing). Options that
# never failed keep their P. With w = 1, 48 campaigns with hidden failures: 291 -> 203 failed experiments, 66 -> 28 in
# the second halves; with failures at random the same regret (benchmarks/README.md, round fifteen). With many options
# (a molecule library, a grid's cells) each has too few runs for a rate of its own; the kernels share what they learn.
OPTION_PRIOR_WEIGHT = 1.0
OPTION_MAX_OPTIONS = 10


def weight(p_feasible: np.ndarray, approach: str) -> np.ndarray:
    """The factor fwa and fwt weigh the acquisition by: P itself (fwa), or P / FWT_THRESHOLD up to 1 (fwt)."""
    if approach == "fwt":
        return np.minimum(1.0, p_feasible / FWT_THRESHOLD)
    return p_feasible


def option_counts(space: SearchSpace, X: np.ndarray, failed: np.ndarray) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """By dim of each categorical parameter with 2 to OPTION_MAX_OPTIONS options: the successful runs and all runs of
    each option among the experiments X (none with OPTION_PRIOR_WEIGHT 0: the option factors are off)."""
    if OPTION_PRIOR_WEIGHT <= 0:
        return {}
    out = {}
    for d in space.small_categorical_dims(OPTION_MAX_OPTIONS):
        out[d] = (space.option_tally(X[~failed], d), space.option_tally(X, d))
    return out


def option_factors(counts: dict[int, tuple[np.ndarray, np.ndarray]], prior: float) -> dict[int, np.ndarray]:
    """The factor of each option on P(feasible), min(1, r / prior), r the option's success rate with `prior` worth
    OPTION_PRIOR_WEIGHT runs; `counts`: option_counts."""
    return {d: np.minimum(1.0, (successes + OPTION_PRIOR_WEIGHT * prior) / (runs + OPTION_PRIOR_WEIGHT) / prior)
            for d, (successes, runs) in counts.items()}


def failing_options(space: SearchSpace, counts: dict[int, tuple[np.ndarray, np.ndarray]],
                    factors: dict[int, np.ndarray]) -> str:
    """What a proposal's meta says of the options whose factor at least halves P: "base=Cs2CO3 (0 of 4 succeeded)",
    "; "-separated ("" for none)."""
    return "; ".join(f"{space.names[d]}={space.parameters[d].options[o]} ({counts[d][0][o]} of {counts[d][1][o]} "
                     "succeeded)" for d, factor in factors.items() for o in np.flatnonzero(factor <= 0.5))


def no_descriptors(space: SearchSpace) -> dict[int, None]:
    """Descriptor overrides that make every finite dim's kernel treat each option on its own."""
    return {int(d): None for d in space.finite_idx}


class Classifier(Protocol):
    def probability(self, X: np.ndarray) -> np.ndarray: ...


class WideKernels:
    """P(feasible) from kernels as wide as the spacing of the data, descriptors shared, constant prior pi worth
    WIDE_PRIOR_WEIGHT observations."""

    def __init__(self, space: SearchSpace, X: np.ndarray, labels: np.ndarray, prior: float, feasible_fraction: float,
                 generator: torch.Generator, descriptors: Mapping[int, np.ndarray] | None = None):
        self._acquisition = Acquisition(KernelDensity(space, X, labels, feasible_fraction, generator,
                                                      spacing_scaled=True, descriptors=descriptors), 1.0 - prior,
                                        WIDE_PRIOR_WEIGHT)

    def probability(self, X: np.ndarray) -> np.ndarray:
        return 1.0 - self._acquisition.evaluate(X)


class FeasibilityModel:
    def __init__(self, space: SearchSpace, X: np.ndarray, failed: np.ndarray, feasible_fraction: float,
                 generator: torch.Generator, descriptors: Mapping[int, np.ndarray] | None = None,
                 classifier: Classifier | None = None):
        """`classifier`: the prior of the narrow kernels (default: the wide kernel estimate)."""
        self.fraction_failed = float(failed.mean())
        # what the planner records in proposal meta about this model: options that keep failing, a fallback
        self.notes: dict[str, str] = {}
        self.prior = (len(failed) - failed.sum() + 1.0) / (len(failed) + 2.0)
        labels = failed.astype(float)
        self._wide = classifier if classifier is not None else WideKernels(space, X, labels, self.prior,
                                                                           feasible_fraction, generator, descriptors)
        narrow = KernelDensity(space, X, labels, feasible_fraction, generator, descriptors=no_descriptors(space))
        self._narrow = (Acquisition(narrow, 0.0), Acquisition(narrow, 1.0))
        counts = option_counts(space, X, np.asarray(failed, dtype=bool))
        self.option_factors = option_factors(counts, self.prior)
        failing = failing_options(space, counts, self.option_factors)
        if failing:
            self.notes["failing_options"] = failing

    def probability(self, X: np.ndarray) -> np.ndarray:
        """(M, D) internal points -> (M,) P(feasible): Gryffin's narrow kernels, each option on its own, with the
        wide estimate (kernels as wide as the data spacing, descriptors shared, or the GP classifier) as their
        prior instead of a constant: near observations the narrow kernels decide, elsewhere the prior extends what was
        seen; times the factor of each option the point holds (`option_factors`)."""
        prior = self._wide.probability(X)
        alpha0, alpha1 = (a.evaluate(X) for a in self._narrow)  # S_fail/(S+u) and (S_fail+u)/(S+u)
        p = 1.0 - alpha0 - (1.0 - prior) * (alpha1 - alpha0)
        for d, factor in self.option_factors.items():
            p = p * factor[np.rint(X[:, d]).astype(int)]
        return p


def combine(alpha: np.ndarray, p_feasible: np.ndarray, approach: str, feas_param: float,
            fraction_failed: float) -> np.ndarray:
    """The score to minimize over a candidate set, from alpha and P(feasible). alpha is first rescaled to a in [0, 1]
    over the set. fwa: -(1 - a) P; fwt: -(1 - a) min(1, P / FWT_THRESHOLD). fia: w (1 - P) + (1 - w) a,
    w = fraction_failed^feas_param. fca: a where P > threshold (feas_param, halved until at least 10 % of the
    candidates pass), +inf elsewhere."""
    span = alpha.max() - alpha.min()
    a = (alpha - alpha.min()) / span if span > 0 else np.zeros_like(alpha)
    if approach in ("fwa", "fwt"):
        return -(1.0 - a) * weight(p_feasible, approach)
    if approach == "fia":
        w = fraction_failed ** feas_param
        return w * (1.0 - p_feasible) + (1.0 - w) * a
    threshold = feas_param
    while (p_feasible > threshold).mean() < FCA_MIN_PASSING and threshold > 1e-6:
        threshold *= 0.5
    return np.where(p_feasible > threshold, a, np.inf)
