"""The planner's view of the feasible region of its known constraints, computed once per campaign and shared by
every ask: V_C, the constraints that exclude nothing, the whole feasible set of a small finite space, and uniform
feasible draws (rejection sampling, then walks inside the region when uniform draws are too rare)."""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from ..config import GeneralSettings
from ..constraints import FeasibleFraction, KnownConstraints, estimate_feasible_fraction, vacuous_constraints
from ..constraints.sampling import hit_and_run, rejection_sample, spread_seeds
from ..errors import ExhaustedSpaceError, NoFeasiblePointError
from .selection import duplicates

logger = logging.getLogger("gryffin_ros.planner")

# Finite spaces with at most this many feasible points are searched exhaustively instead of from random starts.
EXHAUSTIVE_LIMIT = 20_000
# Walks start from up to SPREAD_SEEDS known feasible points chosen far apart; V_C from at most MAX_VC_SAMPLES draws.
SPREAD_SEEDS = 16
MAX_VC_SAMPLES = 2_000_000


class FeasibleRegion:
    def __init__(self, constraints: KnownConstraints, general: GeneralSettings, seed: int):
        self.constraints, self.space, self.general, self.seed = constraints, constraints.space, general, seed
        self._fraction: FeasibleFraction | None = None
        self._finite: np.ndarray | None = None
        self._warnings: list[str] | None = None
        # walks inside the region from known feasible points (hit-and-run); benchmarks swap it out to compare with
        # rejection sampling alone
        self.walk = hit_and_run

    @property
    def warnings(self) -> list[str]:
        """One warning per known constraint that excludes no point of the domain (computed once, and logged then:
        a constraint that constrains nothing is almost always a mistake)."""
        if self._warnings is None:
            self._warnings = vacuous_constraints(self.constraints, np.random.default_rng([self.seed, 3]))
            for text in self._warnings:
                logger.warning(text)
        return list(self._warnings)

    def fraction(self, known_feasible: bool = False) -> FeasibleFraction:
        """V_C: given in the config, exact for finite spaces up to 10^6 points, else Monte Carlo (cached). The first
        time, constraints that exclude nothing are also looked for (`warnings`). `known_feasible`: experiments have
        been reported (feasible points), so a region too small for uniform draws is no error."""
        if self._fraction is None:
            self.warnings  # noqa: B018 - computed (and logged) when the campaign's domain is first studied
            if self.general.feasible_fraction is not None:
                self._fraction = FeasibleFraction(float(self.general.feasible_fraction), 0.0, "given")
            else:
                # a stream of its own that depends on the seed alone: V_C must not change with campaign progress
                rng = np.random.default_rng([self.seed, 1])
                try:
                    self._fraction = estimate_feasible_fraction(self.constraints, rng, max_samples=MAX_VC_SAMPLES)
                except NoFeasiblePointError:
                    if not known_feasible:
                        raise
                    # uniform sampling found nothing, but reported experiments are feasible points: V_C is below
                    # ~1/draws; proposals come from hit-and-run chains started at those experiments
                    self._fraction = FeasibleFraction(1.0 / MAX_VC_SAMPLES, 0.0, "upper_bound", MAX_VC_SAMPLES)
        return self._fraction

    def pool(self, *known: np.ndarray) -> np.ndarray:
        """Known feasible points: the `known` ones (observed, pending) and uniform hits met while estimating V_C."""
        fraction = self.fraction(known_feasible=any(len(k) for k in known))
        parts = list(known)
        if fraction.points is not None:
            parts.append(fraction.points)
        return np.concatenate(parts)

    def finite_set(self) -> np.ndarray | None:
        """Every feasible point of a finite space small enough to search exhaustively, else None (cached)."""
        size = self.space.finite_size
        if size is None or size > 50 * EXHAUSTIVE_LIMIT:
            return None
        if self._finite is None:
            points = self.space.enumerate()
            self._finite = points[self.constraints.feasible(points)]
        return self._finite if len(self._finite) <= EXHAUSTIVE_LIMIT else None

    def random_points(self, n: int, rng: np.random.Generator, avoid: np.ndarray, pool: Callable[[], np.ndarray],
                      known_feasible: bool = False) -> np.ndarray:
        """n feasible points drawn uniformly, none duplicating `avoid` or each other in a finite space; `pool()` gives
        the known feasible points walks start from when uniform draws are too rare."""
        feasible = self.finite_set()
        if feasible is not None:
            free = feasible[~duplicates(self.space, feasible, avoid)]
            if len(free) < n:
                raise ExhaustedSpaceError(
                    f"only {len(free)} feasible point(s) of the search space are neither observed nor pending; "
                    f"{n} requested")
            return free[rng.choice(len(free), n, replace=False)]
        chosen = np.empty((0, self.space.dim))

        def add_new(candidates: np.ndarray) -> bool:
            """Take candidates that repeat neither `avoid` nor each other until n are chosen; True once they are."""
            nonlocal chosen
            for x in candidates:
                if len(chosen) < n and not duplicates(self.space, x[None], np.concatenate([avoid, chosen]))[0]:
                    chosen = np.concatenate([chosen, x[None]])
            return len(chosen) == n

        for _ in range(20):
            X = rejection_sample(self.constraints, rng, 4 * (n - len(chosen)), self.general.max_rejection_draws,
                                 self.fraction(known_feasible).value)
            if not len(X):
                break
            if add_new(X):
                return chosen
        # uniform draws are too rare to hit the feasible set: walk inside it from the feasible points known so far
        seeds = spread_seeds(self.space, pool(), SPREAD_SEEDS, rng)
        if add_new(self.walk(self.constraints, rng, seeds, 20 * n)):
            return chosen
        raise NoFeasiblePointError(
            f"could not draw {n} new feasible point(s) within {self.general.max_rejection_draws} uniform "
            f"samples per try (estimated feasible fraction {self.fraction(known_feasible).value:.2e})")
