"""Geometry of linear constraints in internal coordinates: where a line leaves the half-spaces A u <= b."""

from __future__ import annotations

import numpy as np


def line_limits(A: np.ndarray, b: np.ndarray, X: np.ndarray, V: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For the lines X + t V (rows, internal units), the interval [low, high] of t where A (X + t V) <= b holds
    (-inf / +inf where no half-space bounds it)."""
    slope = V @ A.T
    with np.errstate(divide="ignore", invalid="ignore"):
        limit = (b[None] - X @ A.T) / slope
    return np.where(slope < 0, limit, -np.inf).max(axis=1), np.where(slope > 0, limit, np.inf).min(axis=1)
