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


__all__ = ["Acquisition", "AcquisitionFunction"]
