"""The constrained kernel-density Planner of the paper (Gryffin with known constraints), with the GP surrogate
beside it: models of one ask, start points, candidates from the acquisition optimizer, diversity-aware selection."""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import torch

from ..acquisition import Acquisition, Pinned
from ..acquisition.feasibility import FeasibilityModel, combine, weight
from ..config import PlannerConfig
from ..constraints.sampling import perturb, rejection_sample, spread_seeds
from ..domain import ConstraintArg, Observation
from ..history import History
from ..optimizers import AcquisitionOptimizer, make_optimizer
from ..reporting import report
from ..surrogates.choice import GP_MIN_RESULTS, INITIAL_DESIGN_MAX, SurrogateChoice
from ..surrogates.descriptors import LearnedDescriptors, learn_many
from ..surrogates.kernel_density import KernelDensity
from .base import BasePlanner
from .feasible import SPREAD_SEEDS
from .selection import apart, batch_spacing, select
from .stall import SETTLE_LEAST, STALL_WINDOW, exploring_until, settled, stall

if TYPE_CHECKING:  # the GP modules (and BoTorch, ~0.4 s to import) are loaded only by planners that use a GP
    from ..acquisition import AcquisitionFunction
    from ..surrogates.gaussian_process import GaussianProcess

# general.kernel_width = spacing: continuous kernels of precision SPACING_FACTOR * rho^(2/C), a quarter of the typical
# spacing of the data wide (measured on the paper's continuous benchmarks: factors 4-32 all beat Gryffin's 12 rho^2,
# whose kernels are so narrow that the acquisition is flat between observations; docs/departures.md "Kernel width").
# `auto` uses them up to AUTO_SPACING_MAX_DIMS continuous dims and Gryffin's above, where kernels that wide overlap
# everywhere and every candidate needs every kernel (n = 1000, d = 10: 1.4 s per ask instead of 0.2 s).
SPACING_FACTOR = 16.0
AUTO_SPACING_MAX_DIMS = 4
# Start points: hit-and-run chains from known feasible points, at least WALK_POINTS_PER_SEED points each.
WALK_POINTS_PER_SEED = 8
# Floor of P(feasible) in the GP's constrained EI (log EI + log P): a candidate the failure model rules out entirely
# still ranks, last.
MIN_PROBABILITY = 1e-12
# With feas_approach fwt the GP's expected improvement is weighted by fwt's weight to this power, EI * w^POWER (fwa
# keeps constrained EI, EI * P). With the weight itself, a region that had failed a dozen times still drew experiments
# wherever the GP, extrapolating the feasible results, expected a large improvement: P(feasible) ~ 0.2 there is 1.6
# nats, its EI 5-10 nats more than beside the best feasible result (a quarter of the square failing, Branin's two
# minima inside it: 34 % of experiments 31-60 inside with power 1, 13 % with 3, 9 % with 5; the kernel density's
# rescaled acquisition 7.5 %). benchmarks/README.md, round eight.
FEASIBILITY_POWER = 5.0
# ... and, with fwt, the GP's -log EI beyond EI_FLOOR_NATS (an EI below 1.8 % of the results' standard deviation) counts
# only EI_TAIL_SLOPE as much against P(feasible): 4 + s nats becomes 4 + s / 100. Without it, once a campaign with
# failures had settled, EI was negligible at every candidate (-log EI of 5 to 45 nats) and the least negligible lay
# among failures believed at the incumbent, deep inside the failing region (a quarter holding the unconstrained
# optimum: 44 % of experiments 31-60 deep inside, now 5 %; Branin's quarter: 10 % -> 3 % inside). The tail keeps its
# order: flattened instead (-log(EI + e^-4)), on a finite space P alone then ranked the untried options, and a feasible
# island in a failing ring (Michalewicz without descriptors, seed 12) was reached at 326 of 441 instead of 66.
# Candidates at P >= 0.5 keep EI's order. benchmarks/README.md, round nine.
EI_FLOOR_NATS = 4.0
EI_TAIL_SLOPE = 0.01
# Options of small categorical parameters that every GP proposal covers first: until each option of a categorical
# parameter with 2 to COVER_MAX_OPTIONS options has been run (or is pending) COVER_TRIES times, a GP proposal is the
# best by the acquisition among candidates that hold such an option, the other coordinates optimized under it from
# the COVER_STARTS best candidates. The GP's expected improvement alone left options untried for whole campaigns: on
# m_solvent (6 solvents, 40 experiments) seed 5 never ran 3 of them, the best solvent among them
# (benchmarks/README.md "Stuck campaigns on mixed spaces"). Larger sets (a molecule library) are left to the
# descriptors: trying each option would spend the campaign.
COVER_MAX_OPTIONS = 10
COVER_TRIES = 2
COVER_STARTS = 32
# The fewest successful experiments on the incumbent's combination of options for a GP of their own (`Planner._within`).
WITHIN_LEAST = 4
# An experiment this close to a bound of a continuous condition (internal units, the range being [0, 1]) sits on it.
BOUND_NEAR = 0.02


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
                 seed: int | None = None, history: History | None = None):
        super().__init__(config, known_constraints, seed, history)
        self.surrogate_choice = SurrogateChoice(self.config.general.surrogate, self.space, self.seed,
                                                lambda observations: self.merits(observations, transform=False),
                                                len(self.objectives))

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

    def optimizer(self) -> AcquisitionOptimizer:
        """The acquisition optimizer general.acquisition_optimizer names."""
        return make_optimizer(self.config.general.acquisition_optimizer, self.constraints)

    def start_points(self, rng: np.random.Generator, incumbent: np.ndarray, feasible_observed: np.ndarray
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
            walked = self.region.walk(self.constraints, rng, seeds,
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
        """The model of unknown constraints, once some experiment has failed: Gryffin's narrow kernels over the wide
        kernel estimate or (general.feas_model = gp) over a GP classifier, the kernel estimate if that cannot be
        fitted (`FeasibilityModel.notes` says so)."""
        failed = np.array([o.failed for o in self.observations])
        if not failed.any():
            return None
        descriptors = {d: r.table for d, r in self.learned_descriptors(observed, failed.astype(float)).items()}
        classifier, notes = None, {}
        if self.config.general.feas_model == "gp":
            from ..surrogates.gp_classifier import ClassifierFitError, GPClassifier  # BoTorch, loaded when needed
            seed = int(torch.randint(2**62, (1,), generator=generator))
            try:
                classifier = GPClassifier(self.space, observed, failed, seed, descriptors)
            except ClassifierFitError as error:
                notes = {"feas_model": "kde", "feas_model_reason": str(error)}
        model = FeasibilityModel(self.space, observed, failed, self.feasible_fraction.value, generator, descriptors,
                                 classifier)
        model.notes.update(notes)
        return model

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
            x = self._pick(candidates, score, observed, chosen, rng)
            chosen = np.concatenate([chosen, x[None]])
            points.append(x)
        return np.array(points)

    def _pick(self, candidates: np.ndarray, score: np.ndarray, observed: np.ndarray, chosen: np.ndarray,
              rng: np.random.Generator, diverse: bool = True) -> np.ndarray:
        """The selected candidate (lowest score, no duplicate, spread out unless `diverse` is off), or a random
        feasible point when no candidate is left."""
        index = (select(self.space, candidates, score, observed, chosen, diverse=diverse,
                        dist_param=self.config.general.dist_param) if len(candidates) else None)
        if index is None:
            return self.random_points(1, rng, np.concatenate([observed, chosen]))[0]
        return candidates[index]

    def _surrogates(self, generator: torch.Generator) -> Surrogates:
        """The failure model, then (with a successful experiment) the kernel density of the merits, in that order of
        draws from `generator`."""
        successful = [o for o in self.observations if not o.failed]
        feasibility = self._feasibility(self.observed_points(), generator)
        if not successful:
            return Surrogates(successful, np.empty((0, self.space.dim)), np.empty(0), {}, None, feasibility)
        X = self.observed_points()[np.array([not o.failed for o in self.observations], dtype=bool)]
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

    def with_observations(self, observations=None, draw: int = 0) -> Planner:
        fresh = super().with_observations(observations, draw)
        fresh.surrogate_choice.fits = self.surrogate_choice.fits  # fits of the same data are not made again
        return fresh

    def _propose(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, list[float | None], dict[str, Any]]:
        observed = self.observed_points()
        chosen = self.pending_points()
        generator = torch.Generator().manual_seed(int(rng.integers(2**63)))
        report("models", 0.0)
        models = self._surrogates(generator)
        successful = models.successful
        feasibility = models.feasibility
        if models.density is None:
            if feasibility is None:
                return self.random_points(n, rng, np.concatenate([observed, chosen])), [None] * n, {}
            return self._away_from_failures(n, rng, observed, chosen, feasibility), [None] * n, dict(feasibility.notes)
        X, merits, descriptors, density = models.X, models.merits, models.descriptors, models.density
        levels = len(np.unique(merits))
        if self.surrogate_choice.initial_design(levels, len(merits)):
            meta = {"surrogate": "random", "surrogate_reason": f"initial design: {levels} distinct successful "
                    f"result(s); the GP proposes from {GP_MIN_RESULTS} on, or from {INITIAL_DESIGN_MAX} successful "
                    "experiments"}
            meta.update(feasibility.notes if feasibility is not None else {})
            return self.random_points(n, rng, np.concatenate([observed, chosen])), [None] * n, meta
        gp, meta = self.surrogate_choice.choose(X, merits, successful, density, descriptors)
        meta.update(feasibility.notes if feasibility is not None else {})
        report("optimizing", 0.0)
        incumbent = X[int(np.argmin(merits))]
        start, exhaustive = self.start_points(rng, incumbent, X)
        if gp is not None:
            stalled = self._after_stall(gp, meta)
            points, notes = self._propose_gp(n, rng, gp, start, exhaustive, feasibility, observed, chosen, incumbent,
                                             models, stalled)
            meta.update(notes)
            return points, [None] * n, meta
        return (*self._propose_kde(n, rng, density, start, exhaustive, feasibility, observed, chosen), meta)

    def _after_stall(self, gp: GaussianProcess, meta: dict[str, Any]) -> bool:
        """When the campaign has stalled (`stall`), the GP of this ask predicts what has not been tried at the
        results' mean; the proposals' meta say so. Whether it has."""
        _, values = self.successful_values()
        merits = np.full(len(self.observations), np.nan)
        merits[[not o.failed for o in self.observations]] = self.merits_of_values(values, transform=False)
        covered = self.observed_points()[:, self.space.small_categorical_dims(COVER_MAX_OPTIONS)]
        share = stall(merits, since=exploring_until(covered, COVER_TRIES))
        if share is not None:
            gp.at_results_mean()
            meta["stalled"] = (f"the last {STALL_WINDOW} experiments improved the best result by {100 * share:.2g} % "
                               "of the results' range: untried regions predicted at the results' mean")
        return share is not None

    def _propose_kde(self, n: int, rng: np.random.Generator, density: KernelDensity, start: np.ndarray,
                     exhaustive: bool, feasibility: FeasibilityModel | None, observed: np.ndarray, chosen: np.ndarray
                     ) -> tuple[np.ndarray, list[float | None]]:
        """n points by the kernel density's acquisition, the sampling strategies taken in turn across the campaign,
        spread out by the diversity-aware selection."""
        values = self.strategy_values()
        optimizer = self.optimizer()
        refined: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        points, strategies = [], []
        for i in range(n):
            report("selecting", i / n, i)
            s = float(values[self._drawn % len(values)])
            self._drawn += 1
            if s not in refined:
                refined[s] = self._candidates(Acquisition(density, s), start, exhaustive, optimizer, rng,
                                              feasibility)
            candidates, alpha = refined[s]
            x = self._pick(candidates, alpha, observed, chosen, rng)
            chosen = np.concatenate([chosen, x[None]])
            points.append(x)
            strategies.append(s)
        return np.array(points), strategies

    def _candidates(self, acquisition: AcquisitionFunction, start: np.ndarray, exhaustive: bool,
                    optimizer: AcquisitionOptimizer, rng: np.random.Generator,
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
            probability = feasibility.probability(candidates)
            if general.feas_approach in ("fwa", "fwt") and acquisition.log_scale:
                # the GP's EI weighted by P(feasible) itself (fwa: constrained EI, Gardner et al. 2014) or (fwt) by
                # P / FWT_THRESHOLD up to 1, to the power FEASIBILITY_POWER, -log EI's tail beyond EI_FLOOR_NATS
                # compressed, in log space: its min-max rescaled value is nearly flat where EI is small, and failing
                # regions kept their weight
                power = 1.0
                if general.feas_approach == "fwt":
                    power = FEASIBILITY_POWER
                    alpha = np.where(alpha > EI_FLOOR_NATS, EI_FLOOR_NATS + EI_TAIL_SLOPE * (alpha - EI_FLOOR_NATS),
                                     alpha)
                alpha = alpha - power * np.log(np.maximum(weight(probability, general.feas_approach), MIN_PROBABILITY))
            else:
                alpha = combine(alpha, probability, general.feas_approach, general.feas_param,
                                feasibility.fraction_failed)
        return candidates, alpha

    def _propose_gp(self, n: int, rng: np.random.Generator, gp: GaussianProcess, start: np.ndarray, exhaustive: bool,
                    feasibility: FeasibilityModel | None, observed: np.ndarray, chosen: np.ndarray,
                    incumbent: np.ndarray, models: Surrogates, stalled: bool
                    ) -> tuple[np.ndarray, dict[str, str]]:
        """n points by the GP's expected improvement; failed and pending experiments and the batch's earlier proposals
        enter the GP as believed results (kriging believer), so they are not proposed again and a batch spreads out
        without Gryffin's strategies. The acquisition is optimized once per ask; each further point of a batch is the
        best of those candidates under the updated belief. While some option of a small categorical parameter has
        been run fewer than COVER_TRIES times, a point is the best candidate that holds one (`under_tried`); else,
        when the campaign has settled on one combination of those parameters' options (`settled`), the first point is
        the best result's conditions with one option changed, to a combination not run yet where one is left, else
        with two (`_swaps`); else, on a stalled ask whose best result and most of the last experiments sit on a bound
        of a continuous condition (`_on_bound`), the first point runs it in the other half of its range
        (`_released`). When the first point of an ask after an odd number of experiments runs the best result's
        combination of those options anyway, where in it is decided by a GP of that combination's own experiments
        (`_within`). The second value: the proposals' meta entries that say so."""
        # failed experiments enter as believed results too: the GP learns nothing of the objective from them, so
        # without this their neighbourhood keeps its expected improvement and only P(feasible) holds the planner back
        failed = observed[np.array([o.failed for o in self.observations], dtype=bool)] if feasibility is not None \
            else observed[:0]
        gp.believe(failed, incumbent=False)
        gp.believe(chosen)
        from ..acquisition.gp import GPAcquisition  # BoTorch: loaded by the planners that use a GP
        optimizer = self.optimizer()
        acquisition = GPAcquisition(gp)
        candidates, alpha = self._candidates(acquisition, start, exhaustive, optimizer, rng, feasibility)
        asked = np.concatenate([observed, chosen])
        under = self.under_tried(asked)
        dims = self.space.small_categorical_dims(COVER_MAX_OPTIONS)
        combination = settled(asked[:, dims]) if dims else None
        swaps = None
        # every other ask only: the campaign's GP must see its own choice within the combination run too, or its
        # expected improvement there is never answered and it keeps choosing the combination (a plateau with one good
        # result in a combination: every ask's combination was that one, 9 of 10 asks; round thirty-two)
        within = (combination is None and not under and not exhaustive and bool(dims) and len(self.space.cont_idx) > 0
                  and len(observed) % 2 == 1)
        if combination is not None and not under:  # a settled campaign: the first point runs another combination
            swaps = self._swaps(acquisition, dims, combination, incumbent, optimizer, rng, feasibility, asked)
        bound = self._on_bound(incumbent, observed) if stalled and not under and not exhaustive else None
        if under and not exhaustive:
            pinned, pinned_alpha = self._covering_candidates(acquisition, under, candidates, alpha, optimizer, rng,
                                                             feasibility)
            candidates, alpha = np.concatenate([candidates, pinned]), np.concatenate([alpha, pinned_alpha])
        points, covered, notes = [], [], {}
        spacing = batch_spacing(self.space, n, self.feasible_fraction.value)
        for i in range(n):
            report("selecting", i / n, i)
            if i:  # the believed points changed the acquisition: the optimized candidates are scored again (an
                # optimization per point made a plate of 96 take a minute)
                candidates, alpha = self._candidates(GPAcquisition(gp), candidates, True, optimizer, rng, feasibility)
                alpha = apart(self.space, candidates, alpha, np.array(points), spacing)
            x = None
            if i:
                under = self.under_tried(np.concatenate([observed, chosen]))
            if under:
                holds = np.zeros(len(candidates), dtype=bool)
                for d, option in under:
                    holds |= np.rint(candidates[:, d]) == option
                index = select(self.space, candidates[holds], alpha[holds], observed, chosen, diverse=False,
                               dist_param=self.config.general.dist_param) if holds.any() else None
                if index is not None:
                    x = candidates[holds][index]
                    covered += [f"{self.space.names[d]}={self.space.parameters[d].options[o]}" for d, o in under
                                if round(x[d]) == o]
            if x is None and swaps is not None and len(swaps[0]) and i == 0:
                index = select(self.space, *swaps, observed, chosen, diverse=False,
                               dist_param=self.config.general.dist_param)
                if index is not None:
                    x = swaps[0][index]
                    held = ", ".join(f"{self.space.names[d]}={self.space.parameters[d].options[o]}"
                                     for d, o in zip(dims, combination))
                    notes["settled"] = (f"{SETTLE_LEAST} or more of the last {STALL_WINDOW} experiments ran {held}: "
                                        "this one runs the best result's conditions with one option changed (two "
                                        "when every combination one option away has run)")
            if x is None and bound is not None and i == 0:  # optimized only when no settled swap took the ask
                released = self._released(acquisition, start, candidates, alpha, *bound, optimizer, rng, feasibility)
                index = select(self.space, *released, observed, chosen, diverse=False,
                               dist_param=self.config.general.dist_param) if len(released[0]) else None
                if index is not None:
                    x = released[0][index]
                    d, side = bound
                    notes["off_bound"] = (f"{self.space.names[d]} sat at its {'upper' if side else 'lower'} bound in "
                                          f"{SETTLE_LEAST} or more of the last {STALL_WINDOW} experiments and the "
                                          "campaign stalled: this one runs it in the other half of its range")
            if x is None:
                x = self._pick(candidates, alpha, observed, chosen, rng, diverse=False)
                if within and i == 0 and np.array_equal(np.rint(x[dims]), np.rint(incumbent[dims])):
                    local = self._within(models, dims, incumbent, candidates, alpha, optimizer, rng, feasibility,
                                         failed, chosen)
                    index = select(self.space, local[0], local[1], observed, chosen, diverse=False,
                                   dist_param=self.config.general.dist_param) if local is not None else None
                    if index is not None:
                        x = local[0][index]
                        notes["within"] = (f"the best result's combination of options, where its own "
                                           f"{int(local[2])} experiments' GP expects most")
            chosen = np.concatenate([chosen, x[None]])
            points.append(x)
            if i + 1 < n:
                gp.believe(x[None])
        if covered:
            notes["covering"] = f"options run fewer than {COVER_TRIES} times first: {', '.join(covered)}"
        return np.array(points), notes

    def _swaps(self, acquisition: AcquisitionFunction, dims: list[int], combination: np.ndarray,
               incumbent: np.ndarray, optimizer: AcquisitionOptimizer, rng: np.random.Generator,
               feasibility: FeasibilityModel | None, asked: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The incumbent with one of its options of `dims` changed (to each other option of each), those that the
        known constraints allow and that do not hold the settled `combination`, scored: the conditions that work best
        so far, tried with a neighbouring combination. Not optimized further: optimized in another combination, the
        expected improvement went to conditions nobody had tried (harness m_coupling seed 3 ran another base at 0.5 h
        instead of the best result's 9.7 h, where nothing reacted, and ended 0.093 short instead of 0.040;
        benchmarks/README.md round twenty-three). Only the swaps to combinations that none of `asked` (observed and
        pending experiments) ran, where there are any: the expected improvement favours a combination that ran as
        well as the settled one at other conditions (the trend along them carries over), and a second settled
        campaign followed (harness m_photoredox seed 9 swapped to a catalyst it had run, ended 0.100 short instead
        of 0.011; round twenty-four). When every one of those has run, the untried combinations two options away
        (m_photoredox from scratch, seeds 5 and 16: every neighbour of Ir / DMSO / K2HPO4 had run, the better
        combinations changed catalyst and additive; held out, m_oxidation from scratch with hidden failures, seed 2:
        0.318 -> 0.015 short; round twenty-five); when those have all run too, every swap of one option."""
        run = {tuple(c) for c in np.rint(asked[:, dims]).astype(int).tolist()}
        neighbours = self._changed(incumbent, dims, 1)
        for k in (1, 2):
            swaps = neighbours if k == 1 else self._changed(incumbent, dims, 2)
            untried = np.array([tuple(c) not in run for c in np.rint(swaps[:, dims]).astype(int).tolist()], dtype=bool)
            if untried.any():  # scored, not optimized
                return self._candidates(acquisition, swaps[untried], True, optimizer, rng, feasibility)
        swaps = neighbours[~np.all(np.rint(neighbours[:, dims]).astype(int) == combination, axis=1)]
        if not len(swaps):
            return swaps, np.empty(0)
        return self._candidates(acquisition, swaps, True, optimizer, rng, feasibility)  # scored, not optimized

    def _within(self, models: Surrogates, dims: list[int], incumbent: np.ndarray, candidates: np.ndarray,
                alpha: np.ndarray, optimizer: AcquisitionOptimizer, rng: np.random.Generator,
                feasibility: FeasibilityModel | None, failed: np.ndarray, chosen: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, int] | None:
        """Candidates within the incumbent's combination of options of `dims`, by the expected improvement of a GP of
        that combination's successful experiments alone (`SurrogateChoice.local_gaussian_process`; its `failed` and
        `chosen` (pending) ones believed as in the campaign's GP), optimized with those options pinned from its
        experiments and the best `candidates` moved into it (`_best_moved`); their scores, and how many experiments the
        GP had. None with fewer than WITHIN_LEAST of them. The GP over every combination pools a condition's effect
        across combinations (m_raft: its length scale of the initiator's descriptor was 5, as if every initiator had
        one best temperature); one combination's optimum can lie where the others' does not (benchmarks/README.md
        round thirty-two)."""
        combination = np.rint(incumbent[dims])

        def holding(points: np.ndarray) -> np.ndarray:  # which of `points` run the combination
            return np.all(np.rint(points[:, dims]) == combination, axis=1)

        rows = holding(models.X)
        if rows.sum() < WITHIN_LEAST:
            return None
        from ..acquisition.gp import GPAcquisition

        local = self.surrogate_choice.local_gaussian_process(models.X, models.successful, models.descriptors, rows)
        local.believe(failed[holding(failed)], incumbent=False)
        local.believe(chosen[holding(chosen)])
        acquisition = GPAcquisition(local)
        for d, option in zip(dims, combination):
            acquisition = Pinned(acquisition, d, int(option))
        start = np.concatenate([models.X[rows], self._best_moved(candidates, alpha, dims, combination)])
        points, values = self._candidates(acquisition, start, False, optimizer, rng, feasibility)
        keep = np.isfinite(values)
        return points[keep], values[keep], int(rows.sum())

    def _on_bound(self, incumbent: np.ndarray, observed: np.ndarray) -> tuple[int, float] | None:
        """(dim, bound: 0 or 1) of the continuous condition that the best result sits on a bound of (within
        BOUND_NEAR) and SETTLE_LEAST or more of the last STALL_WINDOW experiments sit on too, the one most of them do;
        None if none."""
        recent = observed[-STALL_WINDOW:]
        found, most = None, 0
        for d in self.space.cont_idx:
            if self.space.periodic[d]:
                continue
            for side in (0.0, 1.0):
                if abs(incumbent[d] - side) > BOUND_NEAR:
                    continue
                count = int((np.abs(recent[:, d] - side) <= BOUND_NEAR).sum())
                if count >= SETTLE_LEAST and count > most:
                    found, most = (int(d), side), count
        return found

    def _released(self, acquisition: AcquisitionFunction, start: np.ndarray, candidates: np.ndarray,
                  alpha: np.ndarray, d: int, side: float, optimizer: AcquisitionOptimizer, rng: np.random.Generator,
                  feasibility: FeasibilityModel | None) -> tuple[np.ndarray, np.ndarray]:
        """Candidates whose condition d lies in the half of its range away from the bound `side` (0 or 1): the start
        points there and the COVER_STARTS best `candidates` with d drawn in it, optimized (d held in that half), those
        the known constraints allow, scored."""
        low, high = (0.0, 0.5) if side else (0.5, 1.0)
        drawn = rng.uniform(low, high, (min(COVER_STARTS, len(candidates)), 1))  # one value of d per moved candidate
        inside = start[(start[:, d] >= low) & (start[:, d] <= high)]
        begin = np.concatenate([inside, self._best_moved(candidates, alpha, [d], drawn)])
        if not len(begin):
            return begin, np.empty(0)
        points, _ = self._candidates(acquisition, begin, False, optimizer, rng, feasibility)
        points[:, d] = np.clip(points[:, d], low, high)
        points = points[self.constraints.feasible(points)]
        if not len(points):
            return points, np.empty(0)
        points, values = self._candidates(acquisition, points, True, optimizer, rng, feasibility)
        keep = np.isfinite(values)
        return points[keep], values[keep]

    def _changed(self, point: np.ndarray, dims: list[int], k: int) -> np.ndarray:
        """`point` with k of its options of `dims` changed, to every other option of each, those that the known
        constraints allow: (M, D), M >= 0."""
        out = []
        for chosen in itertools.combinations(dims, k):
            others = [[o for o in range(int(self.space.n_options[d])) if o != round(point[d])] for d in chosen]
            for options in itertools.product(*others):
                out.append(point.copy())
                out[-1][list(chosen)] = options
        out = np.array(out).reshape(-1, len(point))
        return out[self.constraints.feasible(out)] if len(out) else out

    def under_tried(self, points: np.ndarray) -> list[tuple[int, int]]:
        """(dim, option) of the options of categorical parameters with 2 to COVER_MAX_OPTIONS options that fewer than
        COVER_TRIES of `points` (observed and pending experiments, internal units) hold."""
        out = []
        for d in self.space.small_categorical_dims(COVER_MAX_OPTIONS):
            out += [(d, int(o)) for o in np.flatnonzero(self.space.option_tally(points, d) < COVER_TRIES)]
        return out

    def _best_moved(self, candidates: np.ndarray, alpha: np.ndarray, dims: list[int], options) -> np.ndarray:
        """The COVER_STARTS best `candidates` (by `alpha`) with their values of `dims` set to `options`, those the known
        constraints allow: start points for an optimization under those options."""
        moved = candidates[np.argsort(alpha, kind="stable")[:COVER_STARTS]].copy()
        moved[:, dims] = options
        return moved[self.constraints.feasible(moved)]

    def _covering_candidates(self, acquisition: AcquisitionFunction, under: list[tuple[int, int]],
                             candidates: np.ndarray, alpha: np.ndarray, optimizer: AcquisitionOptimizer,
                             rng: np.random.Generator, feasibility: FeasibilityModel | None
                             ) -> tuple[np.ndarray, np.ndarray]:
        """For each under-tried (dim, option) of `under`: the COVER_STARTS best candidates with that option set (those
        still feasible) and the candidates that hold it, optimized with the option pinned; the results that kept it,
        scored."""
        found, scores = [np.empty((0, self.space.dim))], [np.empty(0)]
        for d, option in under:
            holding = np.flatnonzero(np.rint(candidates[:, d]) == option)
            holding = holding[np.argsort(alpha[holding], kind="stable")[:COVER_STARTS]]
            start = np.concatenate([self._best_moved(candidates, alpha, [d], [option]), candidates[holding]])
            if not len(start):  # no known feasible point holds it: the constraints rule it out here
                continue
            points, values = self._candidates(Pinned(acquisition, d, option), start, False, optimizer, rng,
                                              feasibility)
            keep = np.isfinite(values)
            found.append(points[keep])
            scores.append(values[keep])
        return np.concatenate(found), np.concatenate(scores)
