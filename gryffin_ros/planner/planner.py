"""The ask/tell facade: campaign bookkeeping shared by every strategy, and the constrained kernel-density Planner.

A strategy only implements ``_propose(n, rng)``; validation of observations, pending proposals, determinism
(every random draw derives from the seed, the number of observations and the number of asks), ``best()`` and the
JSON state live in :class:`BasePlanner`.
"""

from __future__ import annotations

import logging
import math
import secrets
import uuid
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import torch

from .acquisition import Acquisition
from .adam_hill import AdamHillOptimizer
from .chimera import Chimera
from .config import PlannerConfig, load_config
from .constraints import FeasibleFraction, KnownConstraints, estimate_feasible_fraction, vacuous_constraints
from .descriptors import LearnedDescriptors, learn_many
from .equalities import LinearEqualities
from .errors import ConfigError, ExhaustedSpaceError, NoFeasiblePointError, ObservationError
from .feasibility import FeasibilityModel, combine
from .genetic import GeneticOptimizer
from .kernel_density import KernelDensity
from .sampling import hit_and_run, perturb, rejection_sample, spread_seeds
from .selection import duplicates, select

if TYPE_CHECKING:  # the GP module (and BoTorch, ~0.4 s to import) is loaded only by planners that use it
    from .gaussian_process import GaussianProcess, GPAcquisition

logger = logging.getLogger(__name__)

STATE_FORMAT = 1
# Finite spaces with at most this many feasible points are searched exhaustively instead of from random starts.
EXHAUSTIVE_LIMIT = 20_000
# general.kernel_width = spacing: continuous kernels of precision SPACING_FACTOR * rho^(2/C), a quarter of the typical
# spacing of the data wide (measured on the paper's continuous benchmarks: factors 4-32 all beat Gryffin's 12 rho^2,
# whose kernels are so narrow that the acquisition is flat between observations; README "Kernel width"). `auto` uses
# them up to AUTO_SPACING_MAX_DIMS continuous dims and Gryffin's above, where kernels that wide overlap everywhere
# and every candidate needs every kernel (n = 1000, d = 10: 1.4 s per ask instead of 0.2 s).
SPACING_FACTOR = 16.0
AUTO_SPACING_MAX_DIMS = 4
# Start points: hit-and-run chains from up to SPREAD_SEEDS known feasible points chosen far apart, at least
# WALK_POINTS_PER_SEED points each; V_C from at most MAX_VC_SAMPLES uniform draws.
SPREAD_SEEDS = 16
WALK_POINTS_PER_SEED = 8
MAX_VC_SAMPLES = 2_000_000
# general.surrogate = auto compares the GP with the kernel density once the successful experiments have this many
# distinct results.
AUTO_MIN_OBSERVATIONS = 5
ConstraintArg = Callable[[dict], bool] | Sequence[Callable[[dict], bool]] | None


def _identity(f: np.ndarray) -> np.ndarray:
    return f


# general.obj_transform on merits in [0, 1] (0 best), as in Gryffin ("identity" is its None), and each inverse:
# sqrt and cbrt accentuate the best region (cbrt more so), square de-emphasizes it
OBJ_TRANSFORMS: dict[str, tuple[Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray], np.ndarray]]] = {
    "sqrt": (np.sqrt, np.square), "cbrt": (np.cbrt, lambda f: f ** 3), "square": (np.square, np.sqrt),
    "identity": (_identity, _identity),
}


@dataclass
class Observation:
    """One reported experiment. ``objectives`` maps each objective name to a float, or None for a failed experiment."""

    params: dict[str, Any]
    objectives: dict[str, float | None]
    experiment_id: str | None = None
    meta: dict[str, Any] = field(default_factory=dict)

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


def _objective_value(name: str, value: Any) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ObservationError(f"objective '{name}' must be a number or null, got {value!r}")
    value = float(value)
    if math.isnan(value):
        return None
    if math.isinf(value):
        raise ObservationError(f"objective '{name}' = {value} is not finite; report a failed experiment as null")
    return value


class BasePlanner:
    """Campaign state and validation shared by the kernel-density Planner and the Random/Genetic baselines."""

    def __init__(self, config: Mapping | str | Path | PlannerConfig, known_constraints: ConstraintArg = None,
                 seed: int | None = None):
        self.config = config if isinstance(config, PlannerConfig) else load_config(config)
        full = self.config.space
        # every parameter the user sees; `space` holds the ones the planner models (equality-solved ones excluded)
        self.parameter_names: tuple[str, ...] = full.names
        self.equalities, specs = LinearEqualities.split(self.config.constraint_specs, full)
        self.space = self.equalities.reduced_space(full) if self.equalities else full
        self.objectives = self.config.objectives
        self.constraints = KnownConstraints.build(self.space, specs, known_constraints, parameters=full.parameters)
        if self.equalities:  # the solved parameters' bounds first; every check sees the solved parameters too
            self.constraints = KnownConstraints(
                self.space, self.equalities.bound_constraints(full) + self.constraints.constraints,
                self.equalities.complete_columns, self._complete)
        self._known_constraints = known_constraints
        if seed is None:
            seed = self.config.general.random_seed
        if seed is None:
            seed = secrets.randbits(63)
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ConfigError(f"seed must be a non-negative integer, got {seed!r}")
        self.seed = int(seed)
        self.observations: list[Observation] = []
        self.pending: dict[str, Proposal] = {}
        self._ask_count = 0
        self._proposal_count = 0
        self._feasible_fraction: FeasibleFraction | None = None
        self._feasible_set: np.ndarray | None = None
        self._constraint_warnings: list[str] | None = None
        self._strategies: np.ndarray | None = None  # sampling strategies replacing the config's (recommend)

    def _complete(self, params: Mapping[str, Any]) -> dict[str, Any]:
        """The modelled parameters of a point -> all parameters (equality-solved ones computed), in config order."""
        return self.equalities.complete(params, self.parameter_names) if self.equalities else dict(params)

    @property
    def ask_count(self) -> int:
        """How many times ask() has run (part of what makes proposals reproducible)."""
        return self._ask_count

    @property
    def proposal_count(self) -> int:
        """How many proposals have been made (the sampling strategies cycle with it)."""
        return self._proposal_count

    # ---- randomness ------------------------------------------------------------------------------------------
    def _rng(self) -> np.random.Generator:
        """Same seed, same observations, same number of asks -> same draws."""
        return np.random.default_rng([self.seed, len(self.observations), self._ask_count, 2])

    # ---- feasible set ----------------------------------------------------------------------------------------
    @property
    def constraint_warnings(self) -> list[str]:
        """One warning per known constraint that excludes no point of the domain (computed once, and logged then:
        a constraint that constrains nothing is almost always a mistake)."""
        if self._constraint_warnings is None:
            self._constraint_warnings = vacuous_constraints(self.constraints, np.random.default_rng([self.seed, 3]))
            for text in self._constraint_warnings:
                logger.warning(text)
        return list(self._constraint_warnings)

    @property
    def feasible_fraction(self) -> FeasibleFraction:
        """V_C: given in the config, exact for finite spaces up to 10^6 points, else Monte Carlo (cached). The first
        time, constraints that exclude nothing are also looked for (`constraint_warnings`)."""
        if self._feasible_fraction is None:
            self.constraint_warnings  # noqa: B018 - computed (and logged) when the campaign's domain is first studied
            given = self.config.general.feasible_fraction
            if given is not None:
                self._feasible_fraction = FeasibleFraction(float(given), 0.0, "given")
            else:
                # a stream of its own that depends on the seed alone: V_C must not change with campaign progress
                rng = np.random.default_rng([self.seed, 1])
                try:
                    self._feasible_fraction = estimate_feasible_fraction(self.constraints, rng,
                                                                         max_samples=MAX_VC_SAMPLES)
                except NoFeasiblePointError:
                    if not self.observations:
                        raise
                    # uniform sampling found nothing, but reported experiments are feasible points: V_C is below
                    # ~1/draws; proposals come from hit-and-run chains started at those experiments
                    self._feasible_fraction = FeasibleFraction(1.0 / MAX_VC_SAMPLES, 0.0, "upper_bound",
                                                               MAX_VC_SAMPLES)
        return self._feasible_fraction

    def feasible_pool(self) -> np.ndarray:
        """Known feasible points: uniform hits met while estimating V_C, observed and pending experiments."""
        fraction = self.feasible_fraction
        parts = [self.observed_points(), self.pending_points()]
        if fraction.points is not None:
            parts.append(fraction.points)
        return np.concatenate(parts)

    def feasible_set(self) -> np.ndarray | None:
        """Every feasible point of a finite space small enough to search exhaustively, else None (cached)."""
        size = self.space.finite_size
        if size is None or size > 50 * EXHAUSTIVE_LIMIT:
            return None
        if self._feasible_set is None:
            points = self.space.enumerate()
            self._feasible_set = points[self.constraints.feasible(points)]
        return self._feasible_set if len(self._feasible_set) <= EXHAUSTIVE_LIMIT else None

    # ---- observations ----------------------------------------------------------------------------------------
    def parse_observation(self, item: Mapping[str, Any] | Observation) -> Observation:
        """Validate one observation: Gryffin style (parameters and objectives as keys, optional experiment_id) or
        structured ``{experiment_id, params, objectives, meta}``. Raises ObservationError naming what is wrong."""
        if isinstance(item, Observation):
            params, objectives, experiment_id, meta = item.params, item.objectives, item.experiment_id, item.meta
        elif isinstance(item, Mapping):
            if "params" in item and "params" not in self.parameter_names:
                unknown = set(item) - {"experiment_id", "params", "objectives", "meta"}
                if unknown:
                    raise ObservationError(f"unknown observation field(s) {sorted(unknown)}")
                params, objectives = item["params"], item.get("objectives")
                experiment_id, meta = item.get("experiment_id"), item.get("meta") or {}
                if objectives is None:
                    objectives = {o.name: None for o in self.objectives}
            else:
                names = {o.name for o in self.objectives}
                unknown = set(item) - set(self.parameter_names) - names - {"experiment_id"}
                if unknown:
                    raise ObservationError(f"unknown key(s) {sorted(unknown)}; parameters are "
                                           f"{list(self.parameter_names)}, objectives {sorted(names)}")
                params = {k: item[k] for k in self.parameter_names if k in item}
                objectives = {o.name: item.get(o.name) for o in self.objectives}
                experiment_id, meta = item.get("experiment_id"), {}
        else:
            raise ObservationError(f"an observation must be a mapping, got {type(item).__name__}")
        if not isinstance(params, Mapping):
            raise ObservationError("'params' must be a mapping")
        if not isinstance(objectives, Mapping):
            raise ObservationError("'objectives' must be a mapping or null")
        if experiment_id is not None and not isinstance(experiment_id, str):
            raise ObservationError(f"experiment_id must be a string, got {experiment_id!r}")
        unknown = set(params) - set(self.parameter_names)
        if unknown:
            raise ObservationError(
                f"unknown parameter(s) {sorted(unknown)}; parameters are {list(self.parameter_names)}")
        X = self.space.to_internal([params])
        clean = self.space.to_params(X)[0]
        for d in self.space.cont_idx:  # keep the caller's exact continuous values, not a unit round trip
            clean[self.space.names[d]] = float(params[self.space.names[d]])
        if self.equalities:
            missing = [n for n in self.equalities.dependent if n not in params]
            if missing:
                raise ObservationError(f"missing parameter(s) {missing}")
            self.config.space.to_internal([params])  # types and bounds of the solved parameters too
            self.equalities.check(params)
            clean = {n: (float(params[n]) if n in self.equalities.dependent else clean[n])
                     for n in self.parameter_names}
        known = {o.name for o in self.objectives}
        extra = set(objectives) - known
        if extra:
            raise ObservationError(f"unknown objective(s) {sorted(extra)}; objectives are {sorted(known)}")
        missing = known - set(objectives)
        if missing:
            raise ObservationError(f"missing objective(s) {sorted(missing)}")
        values = {o.name: _objective_value(o.name, objectives[o.name]) for o in self.objectives}
        violated = self.constraints.violated(clean)
        if violated:
            raise ObservationError(f"parameters {clean} violate the known constraint(s) {violated}")
        return Observation(clean, values, experiment_id, dict(meta))

    def tell(self, observations: Mapping | Observation | Sequence[Mapping | Observation]) -> list[Observation]:
        """Add observations (all or none: the whole batch is validated first). Returns the stored Observations."""
        if isinstance(observations, (Mapping, Observation)):
            observations = [observations]
        parsed = [self.parse_observation(o) for o in observations]
        seen = {o.experiment_id for o in self.observations if o.experiment_id is not None}
        for o in parsed:
            if o.experiment_id is not None:
                if o.experiment_id in seen:
                    raise ObservationError(f"experiment_id '{o.experiment_id}' was already reported")
                seen.add(o.experiment_id)
        self.record(parsed)
        return parsed

    def record(self, observations: Sequence[Observation]) -> None:
        """Add observations that `parse_observation` has already validated (and whose ids are new), without
        validating them again: the path of a campaign that validates each observation once, when it arrives."""
        for o in observations:
            self.observations.append(o)
            if o.experiment_id is not None:
                self.pending.pop(o.experiment_id, None)

    def restore(self, observations: Sequence[Observation], pending: Sequence[Proposal], ask_count: int,
                proposal_count: int) -> None:
        """Put a fresh planner where a campaign left it: its validated observations, the proposals still pending
        and its counters (which, with the seed, make the next proposals the same as without the restart)."""
        if self.observations or self.pending:
            raise RuntimeError("restore() is for a fresh planner")
        self.record(observations)
        self.pending = {p.experiment_id: p for p in pending}
        self._ask_count, self._proposal_count = int(ask_count), int(proposal_count)

    def _internal(self, rows: Sequence[Mapping[str, Any]]) -> np.ndarray:
        return self.space.to_internal(rows) if rows else np.empty((0, self.space.dim))

    def observed_points(self) -> np.ndarray:
        return self._internal([o.params for o in self.observations])

    def pending_points(self) -> np.ndarray:
        return self._internal([p.params for p in self.pending.values()])

    def merits(self, observations: Sequence[Observation], transform: bool = True) -> np.ndarray:
        """Successful observations -> minimization merits in [0, 1]: one objective rescaled (max goals negated),
        several scalarized by Chimera; then (transform) the objective transform (sqrt by default)."""
        if not observations:
            return np.empty(0)
        Y = np.array([[o.objectives[obj.name] for obj in self.objectives] for o in observations], dtype=float)
        if len(self.objectives) > 1:
            f = Chimera(self.objectives, self.config.general.softness).merits(Y)
        else:
            y = -Y[:, 0] if self.objectives[0].goal == "max" else Y[:, 0]
            span = y.max() - y.min()
            f = (y - y.min()) / span if span > 0 else np.zeros_like(y)
        return OBJ_TRANSFORMS[self.config.general.obj_transform][0](f) if transform else f

    def best(self) -> Observation | None:
        """The best successful observation so far (None before the first one)."""
        successful = [o for o in self.observations if not o.failed]
        if not successful:
            return None
        return successful[int(np.argmin(self.merits(successful)))]

    # ---- proposals -------------------------------------------------------------------------------------------
    def ask(self, n: int | None = None) -> list[Proposal]:
        """The next n proposals (default: general.batches); each feasible, none repeating a point of a finite space
        that was observed or is pending."""
        n = self.config.general.batches if n is None else n
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"n must be a positive integer, got {n!r}")
        rng = self._rng()
        points, strategies, meta = self._propose(n, rng)
        self._ask_count += 1
        proposals = []
        for strategy, params in zip(strategies, self.space.to_params(points)):
            proposal = Proposal(str(uuid.uuid4()), self._complete(params), strategy, dict(meta))
            self.pending[proposal.experiment_id] = proposal
            proposals.append(proposal)
        return proposals

    def with_observations(self, observations: Sequence[Mapping[str, Any]] | None = None, draw: int = 0
                          ) -> BasePlanner:
        """A fresh planner of the same config, seed and known constraints that knows exactly `observations` and has
        nothing pending (the feasible-set estimate is shared, not recomputed). `draw` (>= 0) picks another set of
        random draws for the same observations: draw k makes the draws of a planner that has been asked k times."""
        if isinstance(draw, bool) or not isinstance(draw, (int, np.integer)) or draw < 0:
            raise ValueError(f"draw must be a non-negative integer, got {draw!r}")
        fresh = type(self)(self.config, self._known_constraints, self.seed)
        fresh._feasible_fraction, fresh._feasible_set = self._feasible_fraction, self._feasible_set
        fresh._constraint_warnings = self._constraint_warnings
        if observations:
            fresh.tell(list(observations))
        fresh._ask_count = int(draw)
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

    def random_points(self, n: int, rng: np.random.Generator, avoid: np.ndarray) -> np.ndarray:
        """n feasible points drawn uniformly, none duplicating `avoid` or each other in a finite space."""
        feasible = self.feasible_set()
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
            X = rejection_sample(self.constraints, rng, 4 * (n - len(chosen)), self.config.general.max_rejection_draws,
                                 self.feasible_fraction.value)
            if not len(X):
                break
            if add_new(X):
                return chosen
        # uniform draws are too rare to hit the feasible set: walk inside it from the feasible points known so far
        seeds = spread_seeds(self.space, self.feasible_pool(), SPREAD_SEEDS, rng)
        if add_new(hit_and_run(self.constraints, rng, seeds, 20 * n)):
            return chosen
        raise NoFeasiblePointError(
            f"could not draw {n} new feasible point(s) within {self.config.general.max_rejection_draws} uniform "
            f"samples per try (estimated feasible fraction {self.feasible_fraction.value:.2e})")

    # ---- persistence -----------------------------------------------------------------------------------------
    def state(self) -> dict[str, Any]:
        """A JSON-serializable snapshot; ``from_state`` rebuilds an identical planner (pass callables again)."""
        return {
            "format": STATE_FORMAT, "strategy": type(self).__name__, "config": self.config.raw, "seed": self.seed,
            "observations": [o.to_dict() for o in self.observations],
            "pending": [p.to_dict() for p in self.pending.values()],
            "ask_count": self._ask_count, "proposal_count": self._proposal_count,
        }

    @classmethod
    def from_state(cls, state: Mapping[str, Any], known_constraints: ConstraintArg = None,
                   base_dir: str | Path | None = None) -> BasePlanner:
        """Rebuild a planner from `state()`; `base_dir` resolves relative file names in its config."""
        if not isinstance(state, Mapping) or state.get("format") != STATE_FORMAT:
            raise ConfigError(f"not a planner state of format {STATE_FORMAT}")
        if state.get("strategy") != cls.__name__:
            raise ConfigError(f"state was saved by {state.get('strategy')!r}, not {cls.__name__}")
        planner = cls(load_config(state["config"], base_dir), known_constraints, state["seed"])
        planner.restore([planner.parse_observation(o) for o in state["observations"]],
                        [Proposal(p["experiment_id"], p["params"], p.get("strategy"), dict(p.get("meta") or {}))
                         for p in state["pending"]],
                        state["ask_count"], state["proposal_count"])
        return planner


@dataclass
class Surrogates:
    """The models of one ask of the kernel-density Planner (`Planner.surrogates()`)."""

    successful: list[Observation]  # the successful experiments, in order
    X: np.ndarray  # their points, internal units
    merits: np.ndarray  # their merits after general.obj_transform (0 best): what the kernels regress
    descriptors: dict[int, np.ndarray]  # learned descriptor tables by finite dim (general.auto_desc_gen)
    density: KernelDensity | None  # None before the first successful experiment
    feasibility: FeasibilityModel | None  # None until an experiment has failed


class Planner(BasePlanner):
    """Gryffin with known constraints: kernel-density surrogate, lambda strategies, constrained Adam+Hill or genetic
    acquisition optimization, diversity-aware selection; or (general.surrogate) a Gaussian process under the same
    constrained optimizers, or the better ranking of the two on the data so far."""

    def __init__(self, config: Mapping | str | Path | PlannerConfig, known_constraints: ConstraintArg = None,
                 seed: int | None = None):
        super().__init__(config, known_constraints, seed)
        self._gp_fit: tuple[int, dict] | None = None  # (observations fitted, GP hyperparameters) of the last fit
        if self.config.general.surrogate != "kde":
            from .gaussian_process import require_botorch
            require_botorch()

    def strategy_values(self) -> np.ndarray:
        """Sampling strategies s, from exploitation (+1) to exploration (-1); a single strategy is s = 0 (or those
        given to `recommend`)."""
        if self._strategies is not None:
            return self._strategies.copy()
        count = self.config.general.sampling_strategies
        return np.linspace(1.0, -1.0, count) if count > 1 else np.zeros(1)

    @property
    def spacing_kernels(self) -> bool:
        """Whether continuous kernels are spacing-scaled (general.kernel_width; `auto`: up to 4 continuous dims)."""
        width = self.config.general.kernel_width
        return width == "spacing" or (width == "auto" and len(self.space.cont_idx) <= AUTO_SPACING_MAX_DIMS)

    def _optimizer(self) -> AdamHillOptimizer | GeneticOptimizer:
        if self.config.general.acquisition_optimizer == "genetic":
            return GeneticOptimizer(self.constraints)
        return AdamHillOptimizer(self.constraints)

    def _start_points(self, rng: np.random.Generator, incumbent: np.ndarray, feasible_observed: np.ndarray
                      ) -> tuple[np.ndarray, bool]:
        """Start points and whether they are the whole feasible set (then no local refinement is needed)."""
        feasible = self.feasible_set()
        if feasible is not None:
            return feasible, True
        m = self.config.general.num_random_samples * self.space.dim
        uniform = rejection_sample(self.constraints, rng, m, self.config.general.max_rejection_draws,
                                   self.feasible_fraction.value)
        # hit-and-run chains from spread-out known feasible points: they fill in when uniform draws are rare (tiny
        # feasible sets) and give every separate feasible region found a share of start points, however small
        walked = np.empty((0, self.space.dim))
        if self.constraints:
            seeds = spread_seeds(self.space, self.feasible_pool(), SPREAD_SEEDS, rng)
            walked = hit_and_run(self.constraints, rng, seeds,
                                 max(m - len(uniform), WALK_POINTS_PER_SEED * len(seeds)))
        start = np.concatenate([uniform, walked, perturb(self.constraints, rng, incumbent, m)])
        if len(uniform) < m:
            start = np.concatenate([start, feasible_observed])
        return start, False

    def learned_descriptors(self, X: np.ndarray, target: np.ndarray) -> dict[int, LearnedDescriptors]:
        """Dynamic descriptors for each categorical dim with several descriptors (general.auto_desc_gen)."""
        if not self.config.general.auto_desc_gen:
            return {}
        tables = {int(d): self.space.descriptors(d) for d in self.space.finite_idx
                  if self.space.parameters[d].kind == "categorical"}
        dims = [d for d, table in tables.items() if table is not None and table.shape[1] > 1]
        results = learn_many([(tables[d], X[:, d].astype(int)) for d in dims], target)
        return {d: result for d, result in zip(dims, results) if result is not None}

    def descriptor_summary(self) -> dict[str, dict[str, Any]]:
        """What dynamic descriptors learned from the current data, per categorical parameter: for the objective
        model and for the failure model, the relevance of each original descriptor (shares summing to 1) and the
        correlation of each generated descriptor with its target (kept when above 1/sqrt(N - 2))."""
        successful = [o for o in self.observations if not o.failed]
        observed = self.observed_points()
        models = {"objective": self.learned_descriptors(self._internal([o.params for o in successful]),
                                                        self.merits(successful)) if successful else {},
                  "feasibility": self.learned_descriptors(observed, np.array([float(o.failed)
                                                                              for o in self.observations]))}
        summary: dict[str, dict[str, Any]] = {}
        for target, learned in models.items():
            for d, result in learned.items():
                summary.setdefault(self.space.names[d], {})[target] = {
                    "relevance": result.relevance.round(4).tolist(),
                    "correlations": result.correlations.round(4).tolist(), "kept": result.kept.tolist()}
        return summary

    def _feasibility(self, observed: np.ndarray, generator: torch.Generator) -> FeasibilityModel | None:
        """The model of unknown constraints, once some experiment has failed."""
        failed = np.array([o.failed for o in self.observations])
        if not failed.any():
            return None
        descriptors = {d: r.table for d, r in self.learned_descriptors(observed, failed.astype(float)).items()}
        return FeasibilityModel(self.space, observed, failed, self.feasible_fraction.value, generator, descriptors)

    def _away_from_failures(self, n: int, rng: np.random.Generator, observed: np.ndarray, chosen: np.ndarray,
                            feasibility: FeasibilityModel) -> np.ndarray:
        """Nothing has succeeded yet: the feasible candidates most likely to succeed, spread out."""
        candidates = self.feasible_set()
        if candidates is None:
            m = self.config.general.num_random_samples * self.space.dim
            candidates = rejection_sample(self.constraints, rng, m, self.config.general.max_rejection_draws,
                                          self.feasible_fraction.value)
        score = -feasibility.probability(candidates) if len(candidates) else np.empty(0)
        points = []
        for _ in range(n):
            index = (select(self.space, candidates, score, observed, chosen, dist_param=self.config.general.dist_param)
                     if len(candidates) else None)
            x = candidates[index] if index is not None else self.random_points(
                1, rng, np.concatenate([observed, chosen]))[0]
            chosen = np.concatenate([chosen, x[None]])
            points.append(x)
        return np.array(points)

    def _gaussian_process(self, X: np.ndarray, successful: Sequence[Observation],
                          descriptors: Mapping[int, np.ndarray]) -> GaussianProcess:
        """The GP of the untransformed merits (a square root would put a cusp at the optimum), conditioned on every
        successful experiment, with hyperparameters fitted to the first `fit_size(n)` of them (cached; learned
        descriptors change with every observation, so with them every ask fits). Fits are seeded by the campaign
        seed and their size alone, so they never change the draws of the rest of the ask."""
        from .gaussian_process import GaussianProcess, fit_size

        def seed(size: int) -> int:
            return int(np.random.default_rng([self.seed, size, 3]).integers(2**62))

        size = len(X) if descriptors else fit_size(len(X))
        hyperparameters = self._gp_fit[1] if self._gp_fit and self._gp_fit[0] == size else None
        if hyperparameters is None and size < len(X):
            hyperparameters = GaussianProcess(self.space, X[:size], self.merits(successful[:size], transform=False),
                                              seed(size)).hyperparameters
        gp = GaussianProcess(self.space, X, self.merits(successful, transform=False), seed(size), descriptors,
                             hyperparameters)
        if not descriptors:
            self._gp_fit = (size, gp.hyperparameters)
        return gp

    def _choose_surrogate(self, X: np.ndarray, merits: np.ndarray, successful: Sequence[Observation],
                          density: KernelDensity, descriptors: Mapping[int, np.ndarray]
                          ) -> tuple[GaussianProcess | None, dict[str, Any]]:
        """general.surrogate: the GP (or None for the kernel density) and what the proposals record about the choice.

        `auto` compares the two models on the data so far by the rank correlation of their leave-one-out predictions
        with the observed merits (what the acquisition needs is the ordering of points, not calibrated values). The
        GP, which departs from the paper, is used only when it ranks better by more than the sampling error of the
        score (Fisher z of Spearman's r, s.e. sqrt(1.06 / (m - 3))), m the number of distinct merits: tied results
        carry no ranking, so on plateaus (a step-shaped surface with a few levels) the score says little and the
        kernel density stays; never with fewer than AUTO_MIN_OBSERVATIONS distinct merits."""
        surrogate = self.config.general.surrogate
        if surrogate == "kde":
            return None, {"surrogate": "kde"}
        if surrogate == "gp":
            return self._gaussian_process(X, successful, descriptors), {"surrogate": "gp"}
        levels = len(np.unique(merits))
        if levels < AUTO_MIN_OBSERVATIONS:
            return None, {"surrogate": "kde", "surrogate_reason": f"auto: fewer than {AUTO_MIN_OBSERVATIONS} "
                          "distinct successful results"}
        from .gaussian_process import rank_correlation
        gp = self._gaussian_process(X, successful, descriptors)
        scores = {"kde": round(rank_correlation(density.leave_one_out(), merits), 4),
                  "gp": round(rank_correlation(gp.leave_one_out(), merits), 4)}
        z = {name: math.atanh(min(max(r, -0.999), 0.999)) for name, r in scores.items()}
        chosen = "gp" if z["gp"] - z["kde"] > math.sqrt(1.06 / (levels - 3)) else "kde"
        return (gp if chosen == "gp" else None), {"surrogate": chosen, "loo_rank_correlation": scores}

    def _surrogates(self, generator: torch.Generator) -> Surrogates:
        """The failure model, then (with a successful experiment) the kernel density of the merits, in that order of
        draws from `generator`."""
        successful = [o for o in self.observations if not o.failed]
        feasibility = self._feasibility(self.observed_points(), generator)
        if not successful:
            return Surrogates(successful, np.empty((0, self.space.dim)), np.empty(0), {}, None, feasibility)
        X = self._internal([o.params for o in successful])
        merits = self.merits(successful)
        descriptors = {d: r.table for d, r in self.learned_descriptors(X, merits).items()}
        density = KernelDensity(self.space, X, merits, self.feasible_fraction.value, generator,
                                spacing_scaled=self.spacing_kernels, spacing_factor=SPACING_FACTOR,
                                descriptors=descriptors, temperature_scale=self.config.general.concrete_temperature)
        return Surrogates(successful, X, merits, descriptors, density, feasibility)

    def surrogates(self) -> Surrogates:
        """The kernel density and the failure model that the next ask() builds, with the same draws (for
        inspection: regression, P(feasible), acquisition; the GP of general.surrogate is not among them)."""
        rng = self._rng()
        return self._surrogates(torch.Generator().manual_seed(int(rng.integers(2**63))))

    def _propose(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, list[float | None], dict[str, Any]]:
        observed = self.observed_points()
        chosen = self.pending_points()
        generator = torch.Generator().manual_seed(int(rng.integers(2**63)))
        models = self._surrogates(generator)
        successful = models.successful
        feasibility = models.feasibility
        if models.density is None:
            if feasibility is None:
                return self.random_points(n, rng, np.concatenate([observed, chosen])), [None] * n, {}
            return self._away_from_failures(n, rng, observed, chosen, feasibility), [None] * n, {}
        X, merits, descriptors, density = models.X, models.merits, models.descriptors, models.density
        gp, meta = self._choose_surrogate(X, merits, successful, density, descriptors)
        start, exhaustive = self._start_points(rng, X[int(np.argmin(merits))], X)
        if gp is not None:
            return self._propose_gp(n, rng, gp, start, exhaustive, feasibility, observed, chosen), [None] * n, meta
        values = self.strategy_values()
        optimizer = self._optimizer()
        refined: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        points, strategies = [], []
        for _ in range(n):
            s = float(values[self._proposal_count % len(values)])
            self._proposal_count += 1
            if s not in refined:
                refined[s] = self._candidates(Acquisition(density, s), start, exhaustive, optimizer, rng,
                                              feasibility)
            candidates, alpha = refined[s]
            index = (select(self.space, candidates, alpha, observed, chosen, dist_param=self.config.general.dist_param)
                     if len(candidates) else None)
            x = candidates[index] if index is not None else self.random_points(
                1, rng, np.concatenate([observed, chosen]))[0]
            chosen = np.concatenate([chosen, x[None]])
            points.append(x)
            strategies.append(s)
        return np.array(points), strategies, meta

    def _candidates(self, acquisition: Acquisition | GPAcquisition, start: np.ndarray, exhaustive: bool,
                    optimizer: AdamHillOptimizer | GeneticOptimizer, rng: np.random.Generator,
                    feasibility: FeasibilityModel | None) -> tuple[np.ndarray, np.ndarray]:
        """Optimized feasible candidates and their scores (acquisition combined with P(feasible) once experiments
        have failed); the whole feasible set, scored, when it is small enough."""
        if exhaustive:
            candidates, alpha = start, acquisition.evaluate(start)
        else:
            candidates, alpha = optimizer.optimize(acquisition, start, rng)
            keep = self.constraints.feasible(candidates)  # guaranteed by the optimizers; never trusted blindly
            candidates, alpha = candidates[keep], alpha[keep]
        if feasibility is not None:
            general = self.config.general
            alpha = combine(alpha, feasibility.probability(candidates), general.feas_approach, general.feas_param,
                            feasibility.fraction_failed)
        return candidates, alpha

    def _propose_gp(self, n: int, rng: np.random.Generator, gp: GaussianProcess, start: np.ndarray, exhaustive: bool,
                    feasibility: FeasibilityModel | None, observed: np.ndarray, chosen: np.ndarray) -> np.ndarray:
        """n points by the GP's expected improvement; pending experiments and the batch's earlier proposals enter the
        GP as believed results (kriging believer), so a batch spreads out without Gryffin's strategies."""
        gp.believe(chosen)
        optimizer = self._optimizer()
        points = []
        for i in range(n):
            candidates, alpha = self._candidates(gp.acquisition(), start, exhaustive, optimizer, rng, feasibility)
            index = select(self.space, candidates, alpha, observed, chosen, diverse=False) if len(candidates) else None
            x = candidates[index] if index is not None else self.random_points(
                1, rng, np.concatenate([observed, chosen]))[0]
            chosen = np.concatenate([chosen, x[None]])
            points.append(x)
            if i + 1 < n:
                gp.believe(x[None])
        return np.array(points)
