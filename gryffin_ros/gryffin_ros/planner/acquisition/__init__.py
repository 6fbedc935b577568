"""Acquisition functions behind one interface (minimized, `AcquisitionFunction`): Gryffin's kernel-density acquisition
with its sampling strategy (`kernel.Acquisition`) and the GP's expected improvement (`gp.GPAcquisition`, loaded with
BoTorch by the planners that use a GP); and the failure model of unknown constraints, P(feasible) from kernel
acquisitions of the failure labels, with its combination with either (`feasibility`).

This folder reads the surrogates; nothing in `surrogates/` imports from here."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from .kernel import Acquisition


class AcquisitionFunction(Protocol):
    # the scale of the values: True for -log of a positive acquisition (the GP's -log EI: weighting by P(feasible) is
    # adding -log P), False for Gryffin's kernel acquisition (combined with P(feasible) by fwt/fwa/fia/fca)
    log_scale: bool

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """(M, D) internal points -> (M,) acquisition values (lower is better)."""

    def value_and_grad(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values and their gradients with respect to the continuous coordinates."""


class Pinned:
    """An acquisition restricted to the points whose finite dim `dim` holds option `option` (+inf elsewhere): the
    optimizers' Hill moves and genetic children leave that option only for a worse value, so an optimization from
    start points that hold it refines the other coordinates under it."""

    def __init__(self, acquisition: AcquisitionFunction, dim: int, option: int):
        self.acquisition, self.dim, self.option = acquisition, int(dim), int(option)
        self.log_scale = acquisition.log_scale

    def _off(self, X: np.ndarray) -> np.ndarray:
        return np.rint(X[:, self.dim]) != self.option

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        return np.where(self._off(X), np.inf, self.acquisition.evaluate(X))

    def value_and_grad(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        alpha, grad = self.acquisition.value_and_grad(X)
        return np.where(self._off(X), np.inf, alpha), grad


__all__ = ["Acquisition", "AcquisitionFunction", "Pinned"]
