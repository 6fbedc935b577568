"""Unknown constraints learned from failed experiments: P(feasible | x) from the kernel densities of successful and
failed observations, and its combination with the acquisition (fwa, fia, fca).

P(feasible | x) = (sum_{k ok} p_k(x) + pi * u) / (sum_k p_k(x) + u), where u = 1/V is the uniform density acting as one
prior pseudo-observation and pi = (n_ok + 1) / (n + 2) the smoothed prior. Far from every observation P = pi; near
failures P -> 0. This is 1 - alpha of the kernel acquisition with merits = failure labels and strategy s = 1 - pi, so
the same numerics (log space, no underflow) serve both.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import torch

from .acquisition import Acquisition
from .kernel_density import KernelDensity
from .space import SearchSpace

APPROACHES = ("fwa", "fia", "fca")
FCA_MIN_PASSING = 0.1


class FeasibilityModel:
    def __init__(self, space: SearchSpace, X: np.ndarray, failed: np.ndarray, feasible_fraction: float,
                 generator: torch.Generator, descriptors: Mapping[int, np.ndarray] | None = None):
        self.fraction_failed = float(failed.mean())
        self.prior = (len(failed) - failed.sum() + 1.0) / (len(failed) + 2.0)
        self._scales = [Acquisition(KernelDensity(space, X, failed.astype(float), feasible_fraction, generator,
                                                  spacing_scaled=wide, descriptors=descriptors), 1.0 - self.prior)
                        for wide in (False, True)]

    def probability(self, X: np.ndarray) -> np.ndarray:
        """(M, D) internal points -> (M,) P(feasible), the lower of two estimates: Gryffin's narrow kernels (sharp
        near the observations) and kernels as wide as the data spacing (which extend a failed region beyond its
        failed points)."""
        return 1.0 - np.maximum(*[scale.evaluate(X) for scale in self._scales])


def combine(alpha: np.ndarray, p_feasible: np.ndarray, approach: str, feas_param: float,
            fraction_failed: float) -> np.ndarray:
    """The score to minimize over a candidate set, from alpha and P(feasible). alpha is first rescaled to a in [0, 1]
    over the set. fwa: -(1 - a) P. fia: w (1 - P) + (1 - w) a, w = fraction_failed^feas_param. fca: a where
    P > threshold (feas_param, halved until at least 10 % of the candidates pass), +inf elsewhere."""
    span = alpha.max() - alpha.min()
    a = (alpha - alpha.min()) / span if span > 0 else np.zeros_like(alpha)
    if approach == "fwa":
        return -(1.0 - a) * p_feasible
    if approach == "fia":
        w = fraction_failed ** feas_param
        return w * (1.0 - p_feasible) + (1.0 - w) * a
    threshold = feas_param
    while (p_feasible > threshold).mean() < FCA_MIN_PASSING and threshold > 1e-6:
        threshold *= 0.5
    return np.where(p_feasible > threshold, a, np.inf)
