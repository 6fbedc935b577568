"""Acquisition optimizers behind one interface: given an acquisition function (minimized), start points and a
random generator, return refined feasible candidates and their acquisition values. general.acquisition_optimizer
names one of OPTIMIZERS."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from ..acquisition import AcquisitionFunction
from ..constraints import KnownConstraints
from .adam_hill import AdamHillOptimizer
from .genetic import GeneticOptimizer


class AcquisitionOptimizer(Protocol):
    def __init__(self, constraints: KnownConstraints) -> None: ...

    def optimize(self, acquisition: AcquisitionFunction, start: np.ndarray, rng: np.random.Generator
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Refined candidates (internal units, every one feasible) and their acquisition values."""


OPTIMIZERS: dict[str, type[AcquisitionOptimizer]] = {"adam": AdamHillOptimizer, "genetic": GeneticOptimizer}


def make_optimizer(name: str, constraints: KnownConstraints) -> AcquisitionOptimizer:
    """The optimizer general.acquisition_optimizer names, for these constraints."""
    return OPTIMIZERS[name](constraints)


__all__ = ["OPTIMIZERS", "AcquisitionOptimizer", "AdamHillOptimizer", "GeneticOptimizer", "make_optimizer"]
