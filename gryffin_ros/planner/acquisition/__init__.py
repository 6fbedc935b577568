"""Acquisition functions behind one interface (minimized): Gryffin's kernel-density acquisition with its sampling
strategy (`kernel.Acquisition`) and the GP's expected improvement (`surrogates.gaussian_process.GPAcquisition`, which
lives beside the GP whose posterior it reads and is loaded with BoTorch)."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from .kernel import Acquisition


class AcquisitionFunction(Protocol):
    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """(M, D) internal points -> (M,) acquisition values (lower is better)."""

    def value_and_grad(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values and their gradients with respect to the continuous coordinates."""


__all__ = ["Acquisition", "AcquisitionFunction"]
