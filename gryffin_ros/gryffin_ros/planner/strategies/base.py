"""The ask/tell core shared by every strategy: validation, the feasible set, determinism.

A strategy only implements ``_propose(n, rng)``; validation of observations, determinism (every random draw derives
from the seed, the number of observations and the number of asks) and ``best()`` live in :class:`BasePlanner`. What
it learns from is its `History` (observations, pending proposals, counts), which it is given: its own in-memory one
when used alone, a campaign's snapshot of its store in a `Campaign`. The planner keeps only what it derives from it
(internal coordinates, objective values), grown as the history grows.
"""

from __future__ import annotations

import logging
import secrets
import uuid
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..config import PlannerConfig, load_config
from ..constraints import FeasibleFraction, KnownConstraints
from ..constraints.equalities import LinearEqualities
from ..domain import ConstraintArg, Observation, Proposal
from ..errors import ConfigError
from ..history import History
from ..merit import merits, objective_matrix
from .feasible import FeasibleRegion
from .observations import ObservationReader

logger = logging.getLogger(__name__)


def _identity(f: np.ndarray) -> np.ndarray:
    return f


# general.obj_transform on merits in [0, 1] (0 best), as in Gryffin ("identity" is its None), and each inverse:
# sqrt and cbrt accentuate the best region (cbrt more so), square de-emphasizes it
OBJ_TRANSFORMS: dict[str, tuple[Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray], np.ndarray]]] = {
    "sqrt": (np.sqrt, np.square), "cbrt": (np.cbrt, lambda f: f ** 3), "square": (np.square, np.sqrt),
    "identity": (_identity, _identity),
}


class BasePlanner:
    """Campaign state and validation shared by the kernel-density Planner and the Random/Genetic baselines."""

    def __init__(self, config: Mapping | str | Path | PlannerConfig, known_constraints: ConstraintArg = None,
                 seed: int | None = None, history: History | None = None):
        self.config = config if isinstance(config, PlannerConfig) else load_config(config)
        full = self.config.space
        # every parameter the user sees; `space` holds the ones the planner models (equality-solved ones excluded)
        self.parameter_names: tuple[str, ...] = full.names
        self.equalities, specs = LinearEqualities.split(self.config.constraint_specs, full)
        self.space = self.equalities.reduced_space(full) if self.equalities else full
        self.objectives = self.config.objectives
        # with equalities, the solved parameters' bounds first; every check sees the solved parameters too
        eq = self.equalities
        self.constraints = KnownConstraints.build(
            self.space, specs, known_constraints, parameters=full.parameters,
            first=eq.bound_constraints(full) if eq else (), complete_columns=eq.complete_columns if eq else None,
            complete_row=self._complete if eq else None)
        self._known_constraints = known_constraints
        self._reader = ObservationReader(self.space, full, self.equalities, self.objectives, self.constraints)
        if seed is None:
            seed = self.config.general.random_seed
        if seed is None:
            seed = secrets.randbits(63)
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ConfigError(f"seed must be a non-negative integer, got {seed!r}")
        self.seed = int(seed)
        self.history = History() if history is None else history
        # derived from the history's first observations (they only grow): observed_points() of the first
        # len(_observed), successful_values() of the first _values_upto; `_last` is the last observation each covers
        self._observed: np.ndarray | None = None
        self._observed_last: Observation | None = None
        self._successful: tuple[Observation, ...] = ()
        self._values = np.empty((0, len(self.objectives)))
        self._values_upto, self._values_last = 0, None
        self._drawn = 0  # while an ask runs: proposals that took a sampling strategy so far (they cycle with it)
        # the feasible region of the known constraints: V_C, uniform and walked feasible draws, a finite feasible set
        self.region = FeasibleRegion(self.constraints, self.config.general, self.seed)
        self._strategies: np.ndarray | None = None  # sampling strategies replacing the config's (recommend)

    def _complete(self, params: Mapping[str, Any]) -> dict[str, Any]:
        """The modelled parameters of a point -> all parameters (equality-solved ones computed), in config order."""
        return self.equalities.complete(params, self.parameter_names) if self.equalities else dict(params)

    @property
    def observations(self) -> list[Observation]:
        """The history's observations, in the order they arrived."""
        return self.history.observations

    @property
    def pending(self) -> dict[str, Proposal]:
        """The history's proposals still owed an observation."""
        return self.history.pending

    @property
    def ask_count(self) -> int:
        """How many times ask() has run (part of what makes proposals reproducible)."""
        return self.history.ask_count

    @property
    def proposal_count(self) -> int:
        """How many proposals have taken one of the sampling strategies, which cycle with it: the kernel density's.
        Proposals of the GP and random ones take none and leave it as it was (so it is not the number of proposals
        made; that is the store's count of proposals)."""
        return self.history.proposal_count

    # ---- randomness ------------------------------------------------------------------------------------------
    def _rng(self) -> np.random.Generator:
        """Same seed, same observations, same number of asks -> same draws."""
        return np.random.default_rng([self.seed, len(self.observations), self.ask_count, 2])

    # ---- feasible region ------------------------------------------------------------------------------------
    @property
    def constraint_warnings(self) -> list[str]:
        """One warning per known constraint that excludes no point of the domain (logged when first computed)."""
        return self.region.warnings

    @property
    def feasible_fraction(self) -> FeasibleFraction:
        """V_C: given in the config, exact for finite spaces up to 10^6 points, else Monte Carlo (cached)."""
        return self.region.fraction(known_feasible=bool(self.observations))

    def feasible_pool(self) -> np.ndarray:
        """Known feasible points: uniform hits met while estimating V_C, observed and pending experiments."""
        return self.region.pool(self.observed_points(), self.pending_points())

    def feasible_set(self) -> np.ndarray | None:
        """Every feasible point of a finite space small enough to search exhaustively, else None (cached)."""
        return self.region.finite_set()

    def random_points(self, n: int, rng: np.random.Generator, avoid: np.ndarray) -> np.ndarray:
        """n feasible points drawn uniformly, none duplicating `avoid` or each other in a finite space."""
        return self.region.random_points(n, rng, avoid, self.feasible_pool, bool(self.observations))

    # ---- observations ----------------------------------------------------------------------------------------
    def parse_observation(self, item: Mapping[str, Any] | Observation) -> Observation:
        """Validate one observation: Gryffin style (parameters and objectives as keys, optional experiment_id) or
        structured ``{experiment_id, params, objectives, meta}``. Raises ObservationError naming what is wrong."""
        return self._reader.parse(item)

    def tell(self, observations: Mapping | Observation | Sequence[Mapping | Observation]) -> list[Observation]:
        """Add observations (all or none: the whole batch is validated first). Returns the stored Observations."""
        if isinstance(observations, (Mapping, Observation)):
            observations = [observations]
        parsed = [self.parse_observation(o) for o in observations]
        self.history.check_new(parsed)
        self.history.add_observations(parsed)
        return parsed

    def _covers(self, upto: int, last: Observation | None) -> bool:
        """Whether something derived from `upto` observations ending with `last` still describes the first `upto`
        of the history (a campaign hands the planner a new, longer snapshot of the same observations)."""
        observations = self.observations
        return len(observations) >= upto and (upto == 0 or observations[upto - 1] is last)

    def _internal(self, rows: Sequence[Mapping[str, Any]]) -> np.ndarray:
        return self.space.to_internal(rows) if rows else np.empty((0, self.space.dim))

    def _points(self, observations: Sequence[Observation]) -> np.ndarray:
        """Internal coordinates of observations: those made when they were accepted, the others converted now
        (observations read back from a store)."""
        points = [o.point_in(self.space) for o in observations]
        missing = [i for i, p in enumerate(points) if p is None]
        if missing:
            for i, row in zip(missing, self._internal([observations[i].params for i in missing])):
                points[i] = row
        return np.array(points, dtype=float).reshape(len(observations), self.space.dim)

    def observed_points(self) -> np.ndarray:
        """(n, D) internal coordinates of every observation, read-only; converted once per observation (at thousands
        of observations the conversion of all of them took a tenth of an ask, several times per ask)."""
        if self._observed is not None and not self._covers(len(self._observed), self._observed_last):
            self._observed = None  # another history
        done = 0 if self._observed is None else len(self._observed)
        if self._observed is None or done < len(self.observations):
            new = self._points(self.observations[done:])
            points = new if self._observed is None else np.concatenate([self._observed, new])
            points.flags.writeable = False
            self._observed = points
            self._observed_last = self.observations[-1] if self.observations else None
        return self._observed

    def pending_points(self) -> np.ndarray:
        return self._internal([p.params for p in self.pending.values()])

    def successful_values(self) -> tuple[tuple[Observation, ...], np.ndarray]:
        """The successful observations so far and their (n, objectives) values in users' units, read-only; grown as
        observations are recorded (collecting them from every record took several ms per observation at
        thousands: the node's acknowledgement of each result waited for it)."""
        if not self._covers(self._values_upto, self._values_last):  # another history
            self._successful, self._values = (), np.empty((0, len(self.objectives)))
            self._values_upto, self._values_last = 0, None
        if self._values_upto < len(self.observations):
            new = [o for o in self.observations[self._values_upto:] if not o.failed]
            if new:
                values = np.concatenate([self._values, self._objective_matrix(new)])
                values.flags.writeable = False
                self._successful, self._values = self._successful + tuple(new), values
            self._values_upto, self._values_last = len(self.observations), self.observations[-1]
        return self._successful, self._values

    def _objective_matrix(self, observations: Sequence[Observation]) -> np.ndarray:
        return objective_matrix(self.objectives, observations)

    def merits(self, observations: Sequence[Observation], transform: bool = True) -> np.ndarray:
        """Successful observations -> minimization merits in [0, 1]: one objective rescaled (max goals negated),
        several scalarized by Chimera; then (transform) the objective transform (sqrt by default)."""
        if not observations:
            return np.empty(0)
        return self.merits_of_values(self._objective_matrix(observations), transform)

    def merits_of_values(self, Y: np.ndarray, transform: bool = True) -> np.ndarray:
        """`merits` of the (n, objectives) values of successful observations."""
        if len(Y) == 0:
            return np.empty(0)
        f = merits(self.objectives, Y, self.config.general.softness)
        return OBJ_TRANSFORMS[self.config.general.obj_transform][0](f) if transform else f

    def best(self) -> Observation | None:
        """The best successful observation so far (None before the first one): `merit.best_of` of every
        observation, from the values kept as they arrive."""
        successful, values = self.successful_values()
        return successful[int(np.argmin(self.merits_of_values(values, transform=False)))] if successful else None

    # ---- proposals -------------------------------------------------------------------------------------------
    def ask(self, n: int | None = None) -> list[Proposal]:
        """The next n proposals (default: general.batches); each feasible, none repeating a point of a finite space
        that was observed or is pending; added to the history as pending. Progress goes to the callback of
        `reporting.reporting`, which may stop the ask by raising `Cancelled` (the history is then as before)."""
        proposals, ask_count, proposal_count = self.draw(n)
        self.history.add_proposals(proposals, ask_count, proposal_count)
        return proposals

    def draw(self, n: int | None = None) -> tuple[list[Proposal], int, int]:
        """`ask` without touching the history: the proposals, and the ask and proposal counts a history that takes
        them has after them (a campaign stores the three together, then its history has them)."""
        n = self.config.general.batches if n is None else n
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"n must be a positive integer, got {n!r}")
        rng = self._rng()
        self._drawn = self.history.proposal_count
        points, strategies, meta = self._propose(n, rng)
        proposals = [Proposal(str(uuid.uuid4()), self._complete(params), strategy, dict(meta))
                     for strategy, params in zip(strategies, self.space.to_params(points))]
        return proposals, self.history.ask_count + 1, self._drawn

    def with_observations(self, observations: Sequence[Mapping[str, Any]] | None = None, draw: int = 0
                          ) -> BasePlanner:
        """A fresh planner of the same config, seed and known constraints that knows exactly `observations` and has
        nothing pending (the feasible-set estimate is shared, not recomputed). `draw` (>= 0) picks another set of
        random draws for the same observations: draw k makes the draws of a planner that has been asked k times."""
        if isinstance(draw, bool) or not isinstance(draw, (int, np.integer)) or draw < 0:
            raise ValueError(f"draw must be a non-negative integer, got {draw!r}")
        fresh = type(self)(self.config, self._known_constraints, self.seed)
        fresh.region = self.region  # the same constraints: V_C and the feasible set are not computed again
        if observations:
            fresh.tell(list(observations))
        fresh.history.ask_count = int(draw)
        return fresh

    def recommend(self, observations: Sequence[Mapping[str, Any]] | None = None,
                  sampling_strategies: Sequence[float] | None = None, num_batches: int | None = None,
                  draw: int = 0) -> list[dict[str, Any]]:
        """Gryffin-compatible and stateless: parameter dicts for the given observations, `num_batches` batches
        (default general.batches) of one proposal per sampling strategy, batch by batch. `sampling_strategies`
        (values s, +1 exploit, -1 explore) replace the config's for this call; `draw` as in `with_observations`."""
        general = self.config.general
        fresh = self.with_observations(observations, draw)
        count = general.sampling_strategies
        if sampling_strategies is not None:
            values = np.atleast_1d(np.asarray(sampling_strategies, dtype=float))
            if values.ndim != 1 or not len(values) or not np.all(np.isfinite(values)):
                raise ValueError(f"sampling_strategies must be a non-empty list of finite numbers, got "
                                 f"{sampling_strategies!r}")
            fresh._strategies, count = values, len(values)
        batches = general.batches if num_batches is None else num_batches
        if isinstance(batches, bool) or not isinstance(batches, (int, np.integer)) or batches < 1:
            raise ValueError(f"num_batches must be a positive integer, got {num_batches!r}")
        return [p.params for p in fresh.ask(int(batches) * count)]

    def _propose(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, list[float | None], dict[str, Any]]:
        """n internal points, the sampling strategy of each and what every proposal of this ask records in meta."""
        raise NotImplementedError
