"""Chimera: several objectives, in priority order, scalarized into one merit in [0, 1] (lower is better).

Each objective has a tolerance: relative to its range over the current region of interest, or absolute in its own
units. Points that meet the first objective's tolerance are ranked by the second objective, and so on; a point that
misses a tolerance is ranked by that objective alone, and always below every point that meets it. Soft steps
(sigmoid with `softness`) make the merit continuous; below 1e-5 the steps are hard.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .config import Objective, PlannerConfig

HARD_STEP_SOFTNESS = 1e-5


def _step(value: np.ndarray, softness: float) -> np.ndarray:
    """H(v): 1 for v > 0, 0 for v < 0 (a sigmoid of width `softness`)."""
    if softness < HARD_STEP_SOFTNESS:
        return (value > 0).astype(float)
    return 0.5 * (1.0 + np.tanh(0.5 * value / softness))


class Chimera:
    def __init__(self, objectives: Sequence[Objective], softness: float = 1e-3):
        self.objectives = objectives
        self.softness = softness

    def merits(self, values: np.ndarray) -> np.ndarray:
        """values (n, m) in users' units, objectives in priority order -> (n,) merits in [0, 1], lower better."""
        values = np.asarray(values, dtype=float)
        signs = np.array([-1.0 if o.goal == "max" else 1.0 for o in self.objectives])
        f = values * signs
        low, high = f.min(axis=0), f.max(axis=0)
        span = np.where(high > low, high - low, 1.0)
        f = (f - low) / span
        n, m = f.shape
        domain = np.arange(n)
        shifted, thresholds = np.empty((m + 1, n)), np.empty(m)
        shift = 0.0
        for i, objective in enumerate(self.objectives):
            column = f[domain, i]
            if objective.absolute:  # the tolerance in objective units, normalized like the objective
                threshold = (signs[i] * objective.tolerance - low[i]) / span[i]
            else:
                threshold = column.min() + objective.tolerance * (column.max() - column.min())
            interest = domain[column < threshold]
            if interest.size:
                domain = interest
            thresholds[i] = threshold + shift
            shifted[i] = f[:, i] + shift
            following = f[:, i + 1] if i + 1 < m else f[:, 0]
            shift -= following[domain].max() - threshold
        shifted[m] = f[:, 0] + shift
        merit = shifted[m].copy()
        for i in reversed(range(m)):
            merit = merit * _step(thresholds[i] - shifted[i], self.softness) \
                + _step(shifted[i] - thresholds[i], self.softness) * shifted[i]
        low, high = merit.min(), merit.max()
        return (merit - low) / (high - low) if high > low else np.zeros(n)


def hierarchy(config: PlannerConfig) -> str:
    """Chimera's order in words: "X1_X2 >= 0.9 first, then cost as low as possible"."""
    parts = []
    for objective in config.objectives:
        goal = "as high as possible" if objective.goal == "max" else "as low as possible"
        if objective.tolerance and objective is not config.objectives[-1]:
            sign = ">=" if objective.goal == "max" else "<="
            bound = (f"{objective.tolerance:g}" if objective.absolute
                     else f"within {objective.tolerance:.0%} of its best")
            goal = f"{sign} {bound}" if objective.absolute else bound
        parts.append(f"{objective.name} {goal}")
    return parts[0] + "".join(f", then {part}" for part in parts[1:])


def tolerance_line(objective: Objective, values: np.ndarray) -> float | None:
    """Where an objective's Chimera tolerance lies in its own units: the absolute value, or the relative one over
    the observed range (which moves as the campaign goes on: the final position is drawn)."""
    if not objective.tolerance:
        return None
    if objective.absolute:
        return objective.tolerance
    seen = values[np.isfinite(values)]
    if not len(seen):
        return None
    low, high = seen.min(), seen.max()
    return high - objective.tolerance * (high - low) if objective.goal == "max" else low + objective.tolerance * (
        high - low)
