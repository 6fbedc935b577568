"""The kernel-density surrogate of Phoenics/Gryffin, built directly from the observations (no BNN training).

Every observation k (plus its mirrored copies near continuous bounds) contributes a kernel p_k(x) centred on it.
Continuous dims: a Gaussian with precision tau ~ Gamma(a = 12 rho^2, 1) (rho = n / V_C). Averaged over that prior
the Gaussian becomes a Student-t with 2a >= 24 degrees of freedom and scale 1/sqrt(a); we use its Gaussian limit
(precision a), which differs only in far tails where the uniform term of the acquisition dominates, and which lets
all squared distances come from one matrix product instead of an (M, N, D) tensor. Those kernels are so narrow that
between observations only the uniform term is left, so the planner's default (general.kernel_width = spacing) uses
precision 16 rho^(2/C) instead: kernels a quarter of the typical data spacing wide. Finite dims: concrete
(Gumbel-softmax) draws with temperature 0.5 + c/rho (Gryffin's c = 10; general.concrete_temperature, default 0),
reshaped by descriptor distance, averaged over draws into one
probability table per dim.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping

import numpy as np
import torch

from ..space import SearchSpace

MIRROR_FRACTION = 0.1
CONCRETE_DRAWS = 256
# Probability the concrete logits give the observed option before the Gumbel noise (the rest spread evenly).
OBSERVED_OPTION_WEIGHT = 0.9
DTYPE = torch.float64


def mirror(space: SearchSpace, X: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reflect observations within 10 % of a non-periodic continuous bound: all 2^k combinations of the k near dims.

    X: (n, D) internal points, values: (n,) -> (N, D), (N,) with the originals first.
    """
    points, out_values = [X], [values]
    dims = [d for d in space.cont_idx if not space.periodic[d]]
    for i, x in enumerate(X):
        reflections = []
        for d in dims:
            if x[d] < MIRROR_FRACTION:
                reflections.append((d, -x[d]))
            elif x[d] > 1.0 - MIRROR_FRACTION:
                reflections.append((d, 2.0 - x[d]))
        for r in range(1, len(reflections) + 1):
            for combo in itertools.combinations(reflections, r):
                copy = x.copy()
                for d, value in combo:
                    copy[d] = value
                points.append(copy[None])
                out_values.append(values[i:i + 1])
    return np.concatenate(points), np.concatenate(out_values)


def split(space: SearchSpace, X: np.ndarray) -> tuple[torch.Tensor, torch.Tensor]:
    """(M, D) internal points -> continuous coordinates (M, C) float and option indices (M, F) long."""
    return (torch.as_tensor(X[:, space.cont_idx], dtype=DTYPE),
            torch.as_tensor(np.rint(X[:, space.finite_idx]), dtype=torch.long))


def concrete_table(observed: np.ndarray, n_options: int, temperature: float, descriptors: np.ndarray | None,
                   generator: torch.Generator, draws: int = CONCRETE_DRAWS) -> torch.Tensor:
    """Averaged categorical kernels of one finite dim.

    observed: (N,) option indices -> (N, K) table whose row k is kernel k's probability of each option.
    """
    K = n_options
    logits = torch.full((len(observed), K), math.log((1 - OBSERVED_OPTION_WEIGHT) / (K - 1)), dtype=DTYPE)
    logits[torch.arange(len(observed)), torch.as_tensor(observed, dtype=torch.long)] = math.log(OBSERVED_OPTION_WEIGHT)
    uniform = torch.rand((draws, len(observed), K), generator=generator, dtype=DTYPE).clamp_(1e-12, 1 - 1e-12)
    gumbel = -torch.log(-torch.log(uniform))
    probs = torch.softmax((logits + gumbel) / temperature, dim=-1)  # (draws, N, K)
    if descriptors is not None:
        desc = torch.as_tensor(descriptors, dtype=DTYPE)  # (K, m)
        mean_desc = probs @ desc  # (draws, N, m)
        delta = torch.sqrt(((K * (desc[None, None] - mean_desc[:, :, None])) ** 2).mean(-1))  # (draws, N, K)
        probs = torch.softmax(-delta, dim=-1)
    return probs.mean(0)


class KernelDensity:
    """Kernels of the observed points: log p_k(x) for many candidates at once.

    The surrogate owns no objective logic: it receives the points and their merits f_k in [0, 1].
    """

    def __init__(self, space: SearchSpace, X: np.ndarray, merits: np.ndarray, feasible_fraction: float,
                 generator: torch.Generator, spacing_scaled: bool = False, spacing_factor: float = 1.0,
                 descriptors: Mapping[int, np.ndarray] | None = None, temperature_scale: float = 10.0):
        """spacing_scaled: continuous precision spacing_factor * rho^(2/C) (C continuous dims), i.e. kernel width =
        the typical spacing of rho points in C dims over sqrt(spacing_factor), instead of Gryffin's 12 rho^2 (the
        planner's default, general.kernel_width = spacing, uses factor 16; the classifier of failed experiments 1).
        descriptors: learned descriptor tables replacing the space's for some finite dims (dynamic descriptors).
        temperature_scale: c in the concrete temperature 0.5 + c / rho (Gryffin: 10; the planner's default 0)."""
        self.space = space
        self.observed = np.asarray(X, dtype=float)
        locations, self.origin = mirror(space, X, np.arange(len(X)))  # origin: the observation each kernel mirrors
        values = np.asarray(merits, dtype=float)[self.origin]
        self.n_kernels = len(locations)
        self.rho = self.n_kernels / feasible_fraction
        self.merits = torch.as_tensor(values, dtype=DTYPE)
        c = space.cont_idx
        periodic = space.periodic[c]
        self.loc = torch.as_tensor(locations[:, c][:, ~periodic], dtype=DTYPE)  # (N, C) ordinary dims
        self.loc_periodic = torch.as_tensor(locations[:, c][:, periodic], dtype=DTYPE)  # (N, P)
        self._ordinary = torch.as_tensor(np.flatnonzero(~periodic))
        self._periodic = torch.as_tensor(np.flatnonzero(periodic))
        self.precision = (spacing_factor * self.rho ** (2.0 / max(len(c), 1)) if spacing_scaled
                          else 12.0 * self.rho ** 2)
        self._log_norm = 0.5 * len(c) * math.log(self.precision / (2 * math.pi))
        self._loc_sq = (self.loc ** 2).sum(1)  # (N,)
        temperature = 0.5 + temperature_scale / self.rho
        self.tables = [
            torch.log(concrete_table(locations[:, d].astype(int), int(space.n_options[d]), temperature,
                                     (descriptors or {}).get(d, space.descriptors(d)), generator).clamp_min(1e-300))
            for d in space.finite_idx
        ]  # each (N, K_d)
        self.log_uniform = -space.log_volume

    def log_kernels(self, xc: torch.Tensor, xf: torch.Tensor) -> torch.Tensor:
        """xc: (M, C) continuous coords (may require grad), xf: (M, F) long option indices -> (M, N) log p_k(x)."""
        M = xc.shape[0] if xc.shape[1] else xf.shape[0]
        if xc.shape[1]:
            # log_norm - prec/2 |x - mu|^2 = prec x.mu + (log_norm - prec/2 |x|^2) - prec/2 |mu|^2, in two passes
            x = xc[:, self._ordinary]
            out = torch.addmm(-0.5 * self.precision * self._loc_sq[None], x, self.loc.T, alpha=self.precision)
            out = out + (self._log_norm - 0.5 * self.precision * (x ** 2).sum(1, keepdim=True))
            if self._periodic.numel():
                diff = xc[:, self._periodic][:, None, :] - self.loc_periodic[None]
                out = out - 0.5 * self.precision * ((diff - torch.round(diff)) ** 2).sum(-1)
        else:
            out = torch.zeros((M, self.n_kernels), dtype=DTYPE)
        for j, table in enumerate(self.tables):
            out = out + table.T[xf[:, j]]  # (M, N)
        return out

    def regression(self, xc: torch.Tensor, xf: torch.Tensor) -> torch.Tensor:
        """Kernel regression of the merits: sum f_k p_k / sum p_k, (M,)."""
        weights = torch.softmax(self.log_kernels(xc, xf), dim=1)
        return weights @ self.merits

    def leave_one_out(self, at: np.ndarray | None = None) -> np.ndarray:
        """Kernel regression at each observation (or at the observations of indices `at`) from the kernels of all
        other observations (its mirrored copies left out too): (n,) or (len(at),)."""
        at = np.arange(len(self.observed)) if at is None else np.asarray(at)
        with torch.no_grad():
            log_p = self.log_kernels(*split(self.space, self.observed[at]))
            log_p[torch.as_tensor(self.origin)[None, :] == torch.as_tensor(at)[:, None]] = -math.inf
            return (torch.softmax(log_p, dim=1) @ self.merits).numpy()
