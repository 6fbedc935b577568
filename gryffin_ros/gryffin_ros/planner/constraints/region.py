"""The feasible fraction V_C of the domain (exact or Monte Carlo), and constraints that exclude nothing."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import NoFeasiblePointError
from .known import KnownConstraints

ENUMERATION_LIMIT = 10**6
# Feasible Monte Carlo hits kept from the V_C estimate (all of them, up to this many) as hit-and-run seeds: a region
# 1000x smaller than the rest still holds a few of 20 000 draws.
KEPT_HITS = 50_000


@dataclass(frozen=True)
class FeasibleFraction:
    """V_C, the feasible fraction of the domain, with how it was obtained."""

    value: float
    stderr: float
    method: str  # "given" | "unconstrained" | "enumerated" | "monte_carlo" | "upper_bound"
    samples: int = 0
    # feasible points met while estimating (uniform Monte Carlo hits): seeds for the hit-and-run sampler
    points: np.ndarray | None = field(default=None, compare=False, repr=False)


def estimate_feasible_fraction(constraints: KnownConstraints, rng: np.random.Generator,
                               samples: int = 20000, max_samples: int = 2_000_000) -> FeasibleFraction:
    """Exact enumeration for finite spaces up to 10^6 points, else Monte Carlo with its standard error.

    Monte Carlo keeps doubling the sample when nothing feasible is found, up to ``max_samples``; if still nothing is
    feasible the constraints are taken to exclude (almost) the whole domain and a NoFeasiblePointError is raised.
    """
    space = constraints.space
    if not constraints:
        return FeasibleFraction(1.0, 0.0, "unconstrained")
    size = space.finite_size
    if size is not None and size <= ENUMERATION_LIMIT:
        hits = 0
        points = space.enumerate()
        for start in range(0, len(points), 100_000):
            hits += int(constraints.feasible(points[start:start + 100_000]).sum())
        if hits == 0:
            raise NoFeasiblePointError(f"none of the {size} points of the search space satisfies the known constraints")
        return FeasibleFraction(hits / size, 0.0, "enumerated", size)
    hits, drawn, batch, kept = 0, 0, samples, []
    while True:
        X = space.sample(rng, batch)
        ok = constraints.feasible(X)
        hits += int(ok.sum())
        if sum(len(k) for k in kept) < KEPT_HITS:
            kept.append(X[ok][:KEPT_HITS])
        drawn += batch
        if hits >= 10 or drawn >= max_samples:
            break
        batch = min(drawn, max_samples - drawn)
    if hits == 0:
        raise NoFeasiblePointError(
            f"no point satisfying the known constraints was found in {drawn} uniform samples of the domain "
            f"(feasible fraction below ~{1 / drawn:.1e}); check that the constraints do not contradict each other")
    p = hits / drawn
    return FeasibleFraction(p, math.sqrt(p * (1 - p) / drawn), "monte_carlo", drawn, np.concatenate(kept))


# Points on which each constraint is checked for excluding anything: all of a finite space up to this size (or up to
# ENUMERATION_LIMIT for vectorized constraints), else this many uniform draws.
VACUITY_SAMPLES = 20_000


def vacuous_constraints(constraints: KnownConstraints, rng: np.random.Generator) -> list[str]:
    """A warning for each constraint the user wrote that excludes no point of the domain: exactly over a finite
    space, else over VACUITY_SAMPLES uniform draws. A constraint that constrains nothing is almost always a
    mistake (a bound on the wrong parameter, a limit outside the range, a condition that can never hold)."""
    space = constraints.space
    size = space.finite_size
    points = space.enumerate() if size is not None and size <= ENUMERATION_LIMIT else None
    sample = None
    out = []
    for c in constraints.constraints:
        if c.derived:
            continue
        exact = points is not None and (len(points) <= VACUITY_SAMPLES or c.columns_fn is not None)
        if exact:
            X = points
        else:
            sample = space.sample(rng, VACUITY_SAMPLES) if sample is None else sample
            X = sample
        one = KnownConstraints(space, [c], constraints.complete_columns, constraints.complete_row)
        if one.feasible(X).all():
            where = (f"any of the {len(X)} points of the search space" if exact
                     else f"any of {len(X)} uniform samples of the domain")
            out.append(f"known constraint '{c.name}' excludes no point: it holds at {where}; check it for a "
                       "mistake (a limit outside the parameter's range, a condition that never applies)")
    return out
