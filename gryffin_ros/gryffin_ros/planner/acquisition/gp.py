"""The GP's acquisition: alpha(x) = -log EI(x) of a fitted `surrogates.gaussian_process.GaussianProcess` (its posterior,
with the kriging-believer points it was told), minimized by the planner's constrained optimizers like Gryffin's. Loaded
with BoTorch, by the planners that use a GP."""

from __future__ import annotations

import numpy as np
import torch
from botorch.acquisition.analytic import _log_ei_helper as log_ei_helper  # log(phi(u) + u Phi(u)), stable

from ..surrogates.gaussian_process import CHUNK, GaussianProcess
from ..surrogates.kernel_density import split


class GPAcquisition:
    """alpha(x) = -log EI(x) of the GP against the best observation (standardized units: a constant shift of alpha,
    which the planner's scores never see): the same interface as the kernel acquisition (`evaluate`,
    `value_and_grad`), so Adam/Hill and the genetic optimizer minimize it under the known constraints."""

    log_scale = True  # alpha is -log EI: weighting EI by P(feasible) is adding -log P (AcquisitionFunction)

    def __init__(self, gp: GaussianProcess):
        self.space = gp.space
        self.features = gp.features
        self.posterior = gp.posterior

    def _alpha(self, xc: torch.Tensor, xf: torch.Tensor) -> torch.Tensor:
        mean, sigma = self.posterior.mean_and_sigma(self.features(xc, xf))
        return -(log_ei_helper((self.posterior.best - mean) / sigma) + sigma.log())

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """alpha at (M, D) internal points."""
        xc, xf = split(self.space, X)
        with torch.no_grad():
            return np.concatenate([self._alpha(xc[i:i + CHUNK], xf[i:i + CHUNK]).numpy()
                                   for i in range(0, len(X), CHUNK)]) if len(X) else np.empty(0)

    def value_and_grad(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """alpha (M,) and its gradient w.r.t. the continuous internal coordinates (M, C), by autograd."""
        xc, xf = split(self.space, X)
        alpha, grad = np.empty(len(X)), np.zeros(xc.shape)
        for i in range(0, len(X), CHUNK):
            leaf = xc[i:i + CHUNK].clone().requires_grad_(bool(xc.shape[1]))
            value = self._alpha(leaf, xf[i:i + CHUNK])
            if xc.shape[1]:
                (g,) = torch.autograd.grad(value.sum(), leaf)
                grad[i:i + CHUNK] = g.numpy()
            alpha[i:i + CHUNK] = value.detach().numpy()
        return alpha, grad
