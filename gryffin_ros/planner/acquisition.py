"""Gryffin's acquisition alpha(x) = (sum_k f_k p_k(x) + lambda) / (sum_k p_k(x) + 1/V), lambda = s/V, minimized.

s in [-1, 1] is the sampling strategy: s = +1 favours points near good observations (exploitation), s = -1 points far
from every observation (exploration). Evaluated in log space so narrow kernels never underflow.
"""

from __future__ import annotations

import numpy as np
import torch

from .kernel_density import DTYPE, KernelDensity

# Largest number of (candidate, kernel) pairs evaluated at once; bounds memory for large n and many candidates.
CHUNK_ELEMENTS = 2_000_000


class Acquisition:
    def __init__(self, density: KernelDensity, strategy: float):
        self.density = density
        self.strategy = float(strategy)

    def __call__(self, xc: torch.Tensor, xf: torch.Tensor) -> torch.Tensor:
        """xc: (M, C) continuous coords, xf: (M, F) long option indices -> (M,) alpha."""
        log_p = self.density.log_kernels(xc, xf)  # (M, N)
        log_u = torch.tensor(self.density.log_uniform, dtype=DTYPE)
        shift = torch.maximum(log_p.max(dim=1).values, log_u).detach()
        weights = torch.exp(log_p - shift[:, None])
        uniform = torch.exp(log_u - shift)
        numerator = weights @ self.density.merits + self.strategy * uniform
        denominator = weights.sum(1) + uniform
        return numerator / denominator

    def chunk_size(self) -> int:
        return max(1, CHUNK_ELEMENTS // max(1, self.density.n_kernels))

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """alpha at (M, D) internal points, without gradients."""
        space = self.density.space
        out = np.empty(len(X))
        step = self.chunk_size()
        with torch.no_grad():
            for start in range(0, len(X), step):
                part = X[start:start + step]
                xc = torch.as_tensor(part[:, space.cont_idx], dtype=DTYPE)
                xf = torch.as_tensor(np.rint(part[:, space.finite_idx]), dtype=torch.long)
                out[start:start + step] = self(xc, xf).numpy()
        return out
