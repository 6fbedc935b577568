"""Gryffin's acquisition alpha(x) = (sum_k f_k p_k(x) + lambda) / (sum_k p_k(x) + 1/V), lambda = s/V, minimized.

s in [-1, 1] is the sampling strategy: s = +1 favours points near good observations (exploitation), s = -1 points far
from every observation (exploration). The uniform term 1/V counts as one observation; `prior_weight` w makes it w/V
(and lambda = s w/V). Evaluated in log space so narrow kernels never underflow.

Kernels are narrow (precision 12 rho^2), so far from the data every kernel term underflows next to the uniform one:
there alpha = s and its gradient is 0 to float64 resolution (each term is below e^-CUTOFF of the largest). The
gradient, by torch autograd, is therefore computed only for the points where some kernel is within CUTOFF of the
largest term; in high dimensions or with many observations that is a small minority of the candidates.
"""

from __future__ import annotations

import math

import numpy as np
import torch

from ..surrogates.kernel_density import DTYPE, KernelDensity, split

CUTOFF = 50.0
# Largest number of (candidate, kernel) pairs in one dense pass; bounds memory for large n and many candidates.
CHUNK_ELEMENTS = 2_000_000


class Acquisition:
    log_scale = False  # Gryffin's acquisition values, not a logarithm (AcquisitionFunction)

    def __init__(self, density: KernelDensity, strategy: float, prior_weight: float = 1.0):
        """prior_weight: how many observations the uniform term 1/V counts as (Gryffin: one)."""
        self.density = density
        self.strategy = float(strategy)
        self._log_uniform = density.log_uniform + math.log(prior_weight)

    def _alpha(self, log_p: torch.Tensor, shift: torch.Tensor) -> torch.Tensor:
        # terms below e^-(2 CUTOFF) of the largest are set to exactly 0: they are far below float64 resolution of the
        # result, and left alone they become subnormal numbers, which slow exp and matmul down by ~100x on x86
        relative = log_p - shift[:, None]
        weights = torch.where(relative > -2 * CUTOFF, torch.exp(relative.clamp_min(-2 * CUTOFF)), 0.0)
        uniform = torch.exp(self._log_uniform - shift)
        return (weights @ self.density.merits + self.strategy * uniform) / (weights.sum(1) + uniform)

    def _chunk(self, xc: torch.Tensor, xf: torch.Tensor, with_grad: bool) -> tuple[torch.Tensor, torch.Tensor]:
        """alpha (M,) and d alpha / d xc (M, C) (zeros unless with_grad) for one chunk of points."""
        density = self.density
        alpha = torch.full((len(xc),), self.strategy, dtype=DTYPE)
        grad = torch.zeros_like(xc)
        with torch.no_grad():
            dense = density.log_kernels(xc, xf)  # (M, N)
            largest = dense.amax(dim=1)
            shift = torch.clamp_min(largest, self._log_uniform)
            # rows where some kernel is within CUTOFF of the largest term; elsewhere alpha = s and the gradient is 0
            live = torch.nonzero(largest > shift - CUTOFF).flatten()
            if not len(live):
                return alpha, grad
            alpha[live] = self._alpha(dense[live], shift[live])
        if with_grad and xc.shape[1]:
            leaf = xc[live].clone().requires_grad_(True)
            value = self._alpha(density.log_kernels(leaf, xf[live]), shift[live])
            (grad[live],) = torch.autograd.grad(value.sum(), leaf)
        return alpha, grad

    def _run(self, X: np.ndarray, with_grad: bool) -> tuple[np.ndarray, np.ndarray]:
        xc, xf = split(self.density.space, X)
        alpha, grad = np.empty(len(X)), np.zeros((len(X), xc.shape[1]))
        step = max(1, CHUNK_ELEMENTS // max(1, self.density.n_kernels))
        for start in range(0, len(X), step):
            part = slice(start, start + step)
            a, g = self._chunk(xc[part], xf[part], with_grad)
            alpha[part], grad[part] = a.numpy(), g.numpy()
        return alpha, grad

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """alpha at (M, D) internal points."""
        return self._run(X, with_grad=False)[0]

    def value_and_grad(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """alpha (M,) and its exact gradient w.r.t. the continuous internal coordinates (M, C), by autograd."""
        return self._run(X, with_grad=True)
