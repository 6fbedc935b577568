"""One known constraint as the planner holds it, and the wrapping of a user's Python callable into one."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass
class NamedConstraint:
    """One known constraint. ``columns_fn`` (vectorized over column arrays) is used when present, else ``fn``."""

    name: str
    fn: Callable[[dict], Any]
    columns_fn: Callable[[Mapping[str, np.ndarray]], np.ndarray] | None = None
    # when the constraint is exactly a set of linear half-spaces sum(coefs * x) <= rhs in users' units
    linear: list[tuple[dict[str, float], float]] | None = None
    # made by the planner itself (an equality-solved parameter kept within its bounds), not written by the user
    derived: bool = False


def vectorized(fn: Callable[[Mapping[str, np.ndarray]], Any]) -> Callable:
    """Mark a known constraint as vectorized: it takes a dict of equal-length column arrays (users' units, categorical
    options as strings) and returns one bool per row, so batches of candidates cost one call instead of one each."""
    fn.vectorized = True
    return fn


def callable_constraint(fn: Callable, position: int) -> NamedConstraint:
    name = _callable_name(fn, position)
    if not getattr(fn, "vectorized", False):
        return NamedConstraint(name, fn)

    def one(params: Mapping[str, Any]) -> bool:
        result = np.asarray(fn({k: np.asarray([v]) for k, v in params.items()}))
        return bool(result.reshape(-1)[0]) if result.dtype == bool and result.size == 1 else result

    return NamedConstraint(name, one, fn)


def _callable_name(fn: Callable, position: int) -> str:
    name = getattr(fn, "__name__", None) or type(fn).__name__
    return name if name != "<lambda>" else f"known_constraints[{position}]"
