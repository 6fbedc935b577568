"""Constrained acquisition optimization with Adam (continuous dims, exact torch autograd gradients) and Hill moves
(discrete and categorical dims). A point whose Adam step leaves the feasible set stops at its last feasible position;
a Hill move is kept only when it improves alpha and stays feasible.
"""

from __future__ import annotations

import numpy as np
import torch

from .acquisition import Acquisition
from .constraints import KnownConstraints
from .kernel_density import DTYPE


class AdamHillOptimizer:
    name = "adam"

    def __init__(self, constraints: KnownConstraints, steps: int = 10, learning_rate: float = 0.01):
        self.constraints = constraints
        self.space = constraints.space
        self.steps = steps
        self.learning_rate = learning_rate

    def optimize(self, acquisition: Acquisition, start: np.ndarray, rng: np.random.Generator
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Refine feasible start points (M, D) -> (refined points (M, D), alpha at them (M,)); all stay feasible."""
        space = self.space
        X = start.copy()
        active = np.ones(len(X), dtype=bool)
        c, f = space.cont_idx, space.finite_idx
        xc = torch.tensor(X[:, c], dtype=DTYPE, requires_grad=True)
        adam = torch.optim.Adam([xc], lr=self.learning_rate, betas=(0.9, 0.999))
        alpha = acquisition.evaluate(X)
        for _ in range(self.steps):
            if c.size and active.any():
                self._adam_step(acquisition, adam, xc, X, active)
                alpha = acquisition.evaluate(X)
            if f.size:
                alpha = self._hill_step(acquisition, X, alpha, active, rng)
        return X, alpha

    def _adam_step(self, acquisition: Acquisition, adam: torch.optim.Adam, xc: torch.Tensor, X: np.ndarray,
                   active: np.ndarray) -> None:
        space = self.space
        xf = torch.as_tensor(np.rint(X[:, space.finite_idx]), dtype=torch.long)
        adam.zero_grad()
        step = acquisition.chunk_size()
        for start in range(0, len(X), step):
            # alpha of each point depends only on that point, so the gradient of the chunk's sum is per point
            acquisition(xc[start:start + step], xf[start:start + step]).sum().backward()
        adam.step()
        moved = X.copy()
        moved[:, space.cont_idx] = xc.detach().numpy()
        moved = space.clip(moved)
        idx = np.flatnonzero(active)
        ok = self.constraints.feasible(moved[idx])
        X[idx[ok]] = moved[idx[ok]]
        active[idx[~ok]] = False
        with torch.no_grad():
            # frozen and clipped points restart each step from their accepted position
            xc.copy_(torch.as_tensor(X[:, space.cont_idx], dtype=DTYPE))

    def _hill_step(self, acquisition: Acquisition, X: np.ndarray, alpha: np.ndarray, active: np.ndarray,
                   rng: np.random.Generator) -> np.ndarray:
        space = self.space
        for d in rng.permutation(space.finite_idx):
            idx = np.flatnonzero(active)
            if not idx.size:
                break
            trial = X[idx].copy()
            trial[:, d] = rng.integers(0, space.n_options[d], len(idx))
            trial_alpha = acquisition.evaluate(trial)
            better = trial_alpha < alpha[idx]
            if better.any():
                better[better] = self.constraints.feasible(trial[better])
            X[idx[better]] = trial[better]
            alpha[idx[better]] = trial_alpha[better]
        return alpha
