"""Choosing one proposal among optimized candidates: reward exp(-alpha), zero for duplicates of observed or already
chosen points, times a diversity factor that penalizes closeness to them (characteristic distance range / n^p,
p = general.dist_param, 0.5 by default as in Gryffin).
"""

from __future__ import annotations

import numpy as np

from ..space import SearchSpace

DUPLICATE_DISTANCE = 1e-8


def squared_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(M, D), (N, D) -> (M, N) squared Euclidean distances, via one matrix product (no (M, N, D) tensor)."""
    return np.maximum((a ** 2).sum(1)[:, None] + (b ** 2).sum(1)[None, :] - 2.0 * a @ b.T, 0.0)


def duplicates(space: SearchSpace, candidates: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """(M,) bool: candidate within 1e-8 (squared, scaled units) of any reference point, categories equal."""
    if not len(reference) or not len(candidates):
        return np.zeros(len(candidates), dtype=bool)
    d2 = squared_distances(space.scaled(candidates), space.scaled(reference))
    return (d2 < DUPLICATE_DISTANCE).any(axis=1)


def diversity(space: SearchSpace, candidates: np.ndarray, reference: np.ndarray, n_observations: int,
              dist_param: float = 0.5) -> np.ndarray:
    """min(1, mean_d exp(2 (dist_d - char_dist) / range_d)) over continuous/discrete dims, dist_d measured to the
    nearest reference point; ranges are 1 in scaled units and char_dist = 1 / n^dist_param (Gryffin's dist_param,
    default 0.5: 1 / sqrt(n))."""
    dims = np.array([d for d, p in enumerate(space.parameters) if p.kind != "categorical"], dtype=int)
    if not dims.size or not len(reference):
        return np.ones(len(candidates))
    a, b = space.scaled(candidates)[:, dims], space.scaled(reference)[:, dims]
    nearest = squared_distances(a, b).argmin(axis=1)
    dist = np.abs(a - b[nearest])
    n = max(n_observations, 1)
    char_dist = 1.0 / np.sqrt(n) if dist_param == 0.5 else float(n) ** -dist_param  # the default bit for bit as before
    return np.minimum(1.0, np.exp(2.0 * (dist - char_dist)).mean(axis=1))


def select(space: SearchSpace, candidates: np.ndarray, alpha: np.ndarray, observed: np.ndarray,
           chosen: np.ndarray, diverse: bool = True, dist_param: float = 0.5) -> int | None:
    """Index of the best candidate, or None when every candidate duplicates an observed or chosen point. Without
    `diverse` the best new candidate by alpha alone (the GP's expected improvement already weighs exploration)."""
    reference = np.concatenate([observed, chosen]) if len(chosen) else observed
    allowed = np.isfinite(alpha) & ~duplicates(space, candidates, reference)  # +inf: must not be chosen (fca)
    if not allowed.any():
        return None
    if not diverse:
        return int(np.argmin(np.where(allowed, alpha, np.inf)))
    reward = np.where(allowed, np.exp(-(alpha - alpha[allowed].min())), 0.0)  # shifted: same argmax, no overflow
    return int(np.argmax(reward * diversity(space, candidates, reference, len(observed), dist_param)))
