"""The campaign's merit of its observations, one definition for the planner, the campaign, the CLI's progress line,
the plot, the export and the dashboard: one objective rescaled to [0, 1] (max goals negated), several scalarized by
Chimera (its tolerances relative to what has been observed, so the best of a prefix is judged on that prefix alone);
lower is better. From it, the best observation and the best so far after each one.

Pure: the config's objectives (and `general.softness`) and observations in, numbers out; no planner, constraints or
models are built to rank observations."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .chimera import Chimera
from .config import Objective, PlannerConfig
from .domain import Observation


def objective_matrix(objectives: Sequence[Objective], observations: Sequence[Observation]) -> np.ndarray:
    """(n, objectives) values of successful observations, in the objectives' order and users' units."""
    return np.array([[o.objectives[obj.name] for obj in objectives] for o in observations], dtype=float)


def merits(objectives: Sequence[Objective], values: np.ndarray, softness: float) -> np.ndarray:
    """(n, objectives) values of successful observations -> (n,) merits in [0, 1], lower better."""
    if len(values) == 0:
        return np.empty(0)
    if len(objectives) > 1:
        return Chimera(objectives, softness).merits(values)
    y = -values[:, 0] if objectives[0].goal == "max" else values[:, 0]
    span = y.max() - y.min()
    return (y - y.min()) / span if span > 0 else np.zeros_like(y)


def best_of(config: PlannerConfig, observations: Sequence[Observation]) -> Observation | None:
    """The best successful observation among `observations` (None when none succeeded)."""
    successful = [o for o in observations if not o.failed]
    if not successful:
        return None
    values = objective_matrix(config.objectives, successful)
    return successful[int(np.argmin(merits(config.objectives, values, config.general.softness)))]


def best_so_far(config: PlannerConfig, observations: Sequence[Observation]) -> list[Observation | None]:
    """After each observation, the best successful one up to it. One objective: a running best, O(n); several:
    Chimera on each prefix (its tolerances move with the observed range), O(n^2) in numpy."""
    out: list[Observation | None] = []
    if len(config.objectives) == 1:
        objective = config.objectives[0]
        sign = -1.0 if objective.goal == "max" else 1.0
        best, value = None, np.inf
        for o in observations:
            y = o.objectives[objective.name]
            if y is not None and sign * y < value:
                best, value = o, sign * y
            out.append(best)
        return out
    successful: list[Observation] = []
    for o in observations:
        if not o.failed:
            successful.append(o)
        out.append(best_of(config, successful))
    return out
