"""The best experiment so far, by the campaign's own merit (one objective by its goal; several by Chimera, whose
tolerances are relative to what has been observed, so the best of a prefix is judged on that prefix alone). One
definition shared by the progress bar, the plot, export and the status."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from .domain import Observation

if TYPE_CHECKING:
    from .strategies import BasePlanner


def best_of(judge: BasePlanner, observations: Sequence[Observation]) -> Observation | None:
    """The best successful observation among `observations` (None when none succeeded), judged by `judge`'s
    objectives and merits (its own observations play no part)."""
    successful = [o for o in observations if not o.failed]
    return successful[int(np.argmin(judge.merits(successful, transform=False)))] if successful else None


def best_so_far(judge: BasePlanner, observations: Sequence[Observation]) -> list[Observation | None]:
    """After each observation, the best successful one up to it. One objective: a running best, O(n); several:
    Chimera on each prefix (its tolerances move with the observed range), O(n^2) in numpy."""
    out: list[Observation | None] = []
    if len(judge.objectives) == 1:
        objective = judge.objectives[0]
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
        out.append(best_of(judge, successful))
    return out
