"""Choosing one proposal among optimized candidates: reward exp(-alpha), zero for duplicates of observed or already
chosen points, times a diversity factor that penalizes closeness to them (characteristic distance range / n^p,
p = general.dist_param, 0.5 by default as in Gryffin).
"""

from __future__ import annotations

import numpy as np

from ..space import SearchSpace

# Two points closer than this (Euclidean, continuous dims scaled to [0, 1], every other dim equal) are the same
# experiment: a thousandth of a range is below what a lab sets apart (0.05 degC of 50 degC); proposals 0.02 degC
# from an observation were made when only 1e-4 counted.
DUPLICATE_DISTANCE = 1e-3
# A GP batch keeps its points at least this fraction of the even spacing of the batch apart (batch_spacing).
BATCH_SPACING = 0.25


def squared_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(M, D), (N, D) -> (M, N) squared Euclidean distances, via one matrix product (no (M, N, D) tensor)."""
    return np.maximum((a ** 2).sum(1)[:, None] + (b ** 2).sum(1)[None, :] - 2.0 * a @ b.T, 0.0)


def duplicates(space: SearchSpace, candidates: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """(M,) bool: candidate within DUPLICATE_DISTANCE of a reference point (continuous dims scaled to [0, 1]) with
    the same option in every finite dim (option indices as coordinates: different options are >= 1 apart)."""
    if not len(reference) or not len(candidates):
        return np.zeros(len(candidates), dtype=bool)
    d2 = squared_distances(candidates, reference)
    return (d2 < DUPLICATE_DISTANCE ** 2).any(axis=1)


def ordered_dims(space: SearchSpace) -> np.ndarray:
    """The continuous and discrete dims: those with a distance between options."""
    return np.array([d for d, p in enumerate(space.parameters) if p.kind != "categorical"], dtype=int)


def diversity(space: SearchSpace, candidates: np.ndarray, reference: np.ndarray, n_observations: int,
              dist_param: float = 0.5) -> np.ndarray:
    """min(1, mean_d exp(2 (dist_d - char_dist) / range_d)) over continuous/discrete dims, dist_d measured to the
    nearest reference point; ranges are 1 in scaled units and char_dist = 1 / n^dist_param (Gryffin's dist_param,
    default 0.5: 1 / sqrt(n))."""
    dims = ordered_dims(space)
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


def batch_spacing(space: SearchSpace, n: int, feasible_fraction: float) -> float:
    """Least distance (scaled units, non-categorical dims) between two points of one GP batch of n: BATCH_SPACING
    times the spacing of n points spread evenly over the feasible volume. Kriging-believer EI alone put a plate of 96
    (n = 500, d = 6) inside a box of side 0.1 around the incumbent (least distance 0.002; random feasible points:
    0.17)."""
    dims = len(ordered_dims(space))
    return BATCH_SPACING * (feasible_fraction / max(n, 1)) ** (1.0 / dims) if dims and n > 1 else 0.0


def apart(space: SearchSpace, candidates: np.ndarray, alpha: np.ndarray, batch: np.ndarray,
          spacing: float) -> np.ndarray:
    """alpha with candidates closer than `spacing` to a point already in the batch ruled out (+inf); the spacing is
    halved until some candidate is left."""
    if not spacing or not len(batch):
        return alpha
    dims = ordered_dims(space)
    d2 = squared_distances(space.scaled(candidates)[:, dims], space.scaled(batch)[:, dims]).min(axis=1)
    while spacing > 1e-6:
        near = d2 < spacing ** 2
        if not (near | ~np.isfinite(alpha)).all():
            return np.where(near, np.inf, alpha)
        spacing /= 2
    return alpha
