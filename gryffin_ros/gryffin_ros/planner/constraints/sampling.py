"""Start points for the acquisition optimizers: uniform rejection sampling with a bounded number of draws, and
+-5 % perturbations of the incumbent, both kept only where every known constraint holds.
"""

from __future__ import annotations

import numpy as np

from .geometry import line_limits
from .known import KnownConstraints


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


def spread_seeds(space, points: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
    """Up to k of `points` chosen by farthest-point selection (internal units, finite dims scaled to [0, 1]): every
    separate feasible region that holds one of the points gets a seed, however small it is."""
    if len(points) <= k:
        return points
    scale = np.where(space.continuous, 1.0, 1.0 / np.maximum(space.n_options - 1, 1))
    Z = points * scale
    chosen = [int(rng.integers(len(points)))]
    distance = ((Z - Z[chosen[0]]) ** 2).sum(1)
    for _ in range(k - 1):
        nxt = int(np.argmax(distance))
        if distance[nxt] == 0.0:
            break
        chosen.append(nxt)
        distance = np.minimum(distance, ((Z - Z[nxt]) ** 2).sum(1))
    return points[chosen]


def hit_and_run(constraints: KnownConstraints, rng: np.random.Generator, seeds: np.ndarray, m: int,
                steps: int = 8, shrinks: int = 12) -> np.ndarray:
    """m feasible points from hit-and-run chains started at feasible `seeds` (one chain per seed, run in parallel).

    Each step picks a random direction in the continuous dims and samples the feasible chord through the current
    point: the chord is cut exactly by the box and by the linear constraints (on a polytope every draw is feasible:
    exact hit-and-run); any other constraint is handled by slice sampling with shrinkage: a uniform draw on the
    chord, and on an infeasible draw the chord shrinks towards the current point (at most `shrinks` times; then the
    point stays). Uniform on the feasible set is the chain's stationary distribution; a chain can jump between
    regions that one line crosses. Finite dims take a Metropolis step to a random option, kept when feasible. The
    seeds are returned first, then the chains' points in
    random order. Only feasible points are ever returned; with no seeds, nothing is returned.
    """
    space = constraints.space
    if not len(seeds) or m <= 0:
        return np.empty((0, space.dim))
    chains = int(min(len(seeds), m))
    X = seeds[rng.permutation(len(seeds))[:chains]].copy()
    c, f = space.cont_idx, space.finite_idx
    planes = constraints.halfspaces()
    linear = None if planes is None else planes[:2]
    out = []
    per_chain_steps = max(steps, int(np.ceil(m / chains)))
    for _ in range(per_chain_steps):
        if c.size:
            direction = rng.normal(size=(chains, c.size))
            direction /= np.linalg.norm(direction, axis=1, keepdims=True)
            # the segment of the line inside [0, 1]^C (periodic dims treated as ordinary here)
            with np.errstate(divide="ignore", invalid="ignore"):
                to_low = np.where(direction != 0, -X[:, c] / direction, -np.inf)
                to_high = np.where(direction != 0, (1.0 - X[:, c]) / direction, np.inf)
            lo = np.max(np.minimum(to_low, to_high), axis=1)
            hi = np.min(np.maximum(to_low, to_high), axis=1)
            if linear is not None:  # exact chord through the linear half-spaces: A (x + t v) <= b
                V = np.zeros_like(X)
                V[:, c] = direction
                low, high = line_limits(*linear, X, V)
                lo, hi = np.maximum(lo, low), np.minimum(hi, high)
                hi = np.maximum(hi, lo)  # a seed on the boundary (rounding): an empty chord, the point stays
            pending = np.ones(chains, dtype=bool)
            for _ in range(shrinks):
                idx = np.flatnonzero(pending)
                if not idx.size:
                    break
                t = rng.uniform(lo[idx], hi[idx])
                trial = X[idx].copy()
                trial[:, c] = np.clip(trial[:, c] + t[:, None] * direction[idx], 0.0, 1.0)
                ok = constraints.feasible(trial)
                X[idx[ok]] = trial[ok]
                pending[idx[ok]] = False
                # shrink towards the current point (t = 0), which is feasible
                bad = idx[~ok]
                t_bad = t[~ok]
                lo[bad] = np.where(t_bad < 0, t_bad, lo[bad])
                hi[bad] = np.where(t_bad >= 0, t_bad, hi[bad])
        for d in f:
            trial = X.copy()
            trial[:, d] = rng.integers(0, space.n_options[d], chains)
            ok = constraints.feasible(trial)
            X[ok] = trial[ok]
        out.append(X.copy())
    samples = np.concatenate(out)
    # the seeds themselves come first: a chain may jump to a bigger region along its line (that is correct for
    # sampling the union), so the seed is what guarantees every region found keeps a start point
    samples = np.concatenate([seeds[:m], samples[rng.permutation(len(samples))]])
    return samples[:m]
