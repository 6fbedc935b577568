"""Start points for the acquisition optimizers: uniform rejection sampling with a bounded number of draws, and
+-5 % perturbations of the incumbent, both kept only where every known constraint holds.
"""

from __future__ import annotations

import numpy as np

from .constraints import KnownConstraints


def rejection_sample(constraints: KnownConstraints, rng: np.random.Generator, m: int, max_draws: int,
                     feasible_fraction: float = 1.0) -> np.ndarray:
    """Up to m uniform feasible points (internal units), drawing at most max_draws candidates in total.

    Returns fewer than m rows (possibly none) when the budget runs out; the caller decides what that means.
    """
    space = constraints.space
    found, drawn, total = [], 0, 0
    while total < m and drawn < max_draws:
        batch = int(min(max_draws - drawn, max(256, 1.2 * (m - total) / max(feasible_fraction, 1e-6))))
        X = space.sample(rng, batch)
        drawn += batch
        X = X[constraints.feasible(X)]
        found.append(X)
        total += len(X)
    out = np.concatenate(found) if found else np.empty((0, space.dim))
    return out[:m]


def perturb(constraints: KnownConstraints, rng: np.random.Generator, incumbent: np.ndarray, m: int,
            width: float = 0.05) -> np.ndarray:
    """Up to m feasible points within +-width (fraction of each range) of the incumbent; categories are kept."""
    space = constraints.space
    X = np.repeat(incumbent[None], 2 * m, axis=0)
    c, f = space.cont_idx, space.finite_idx
    if c.size:
        X[:, c] += rng.uniform(-width, width, (len(X), c.size))
    discrete = np.array([d for d in f if space.parameters[d].kind == "discrete"], dtype=int)
    if discrete.size:
        spread = width * (space.n_options[discrete] - 1)
        X[:, discrete] += rng.uniform(-1, 1, (len(X), discrete.size)) * np.maximum(spread, 1.0)
    X = space.clip(X)
    return X[constraints.feasible(X)][:m]
