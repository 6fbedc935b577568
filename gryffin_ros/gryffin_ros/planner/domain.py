"""Domain types shared by the planner, the campaign store and the messages: what was observed and what is proposed."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import ObservationError

# Known constraints given in Python: one callable params -> bool, or several (combined by AND).
ConstraintArg = Callable[[dict], bool] | Sequence[Callable[[dict], bool]] | None


@dataclass
class Observation:
    """One reported experiment. ``objectives`` maps each objective name to a float, or None for a failed experiment."""

    params: dict[str, Any]
    objectives: dict[str, float | None]
    experiment_id: str | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    # (the search space, its row of internal coordinates): made once, when a planner accepts the observation, and
    # read by the planners of that space instead of converting the params again; not part of what was observed
    internal: tuple[Any, np.ndarray] | None = field(default=None, compare=False, repr=False)

    def point_in(self, space: Any) -> np.ndarray | None:
        """The internal coordinates in `space`, if they were made when it was accepted there."""
        return self.internal[1] if self.internal is not None and self.internal[0] is space else None

    @property
    def failed(self) -> bool:
        return any(v is None for v in self.objectives.values())

    def to_dict(self) -> dict[str, Any]:
        out = {"experiment_id": self.experiment_id, "params": dict(self.params), "objectives": dict(self.objectives)}
        if self.meta:
            out["meta"] = dict(self.meta)
        return out


@dataclass
class Proposal:
    """One experiment to run: its id, its parameters in users' units and the sampling strategy that chose it."""

    experiment_id: str
    params: dict[str, Any]
    strategy: float | None = None
    meta: dict[str, Any] = field(default_factory=dict)  # how it was chosen, e.g. {"surrogate": "gp"}

    def to_dict(self) -> dict[str, Any]:
        out = {"experiment_id": self.experiment_id, "params": dict(self.params), "strategy": self.strategy}
        if self.meta:
            out["meta"] = dict(self.meta)
        return out


def objective_value(name: str, value: Any) -> float | None:
    """A reported objective as a float, or None for a failed experiment. NaN and infinities are refused: a failure
    is said explicitly (None here, null in JSON, failed = true in a typed message), never as a number."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ObservationError(f"objective '{name}' must be a number or null, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ObservationError(f"objective '{name}' = {value} is not finite, not a result; report a failed experiment "
                               "as None (JSON null, failed = true in a typed observation)")
    return value
