"""general.surrogate: which regression model the next proposals come from — the paper's kernel density (`kde`), a
Gaussian process (`gp`), the better ranking of the two on the data so far starting from the kernel density (`auto`),
or (`portfolio`, the default) the same comparison starting from the model that suits the problem's shape — with the
GP's fitted hyperparameters cached between asks, and between the fresh planners of stateless `recommend` calls."""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..domain import Observation
from ..space import SearchSpace
from .kernel_density import KernelDensity

if TYPE_CHECKING:  # BoTorch (~0.4 s to import) is loaded only when a GP is used
    from .gaussian_process import GaussianProcess

SURROGATES = ("portfolio", "kde", "gp", "auto")
# `auto` compares the GP with the kernel density once the successful experiments have this many distinct results.
AUTO_MIN_OBSERVATIONS = 5
# A GP is not asked for proposals before the successful experiments have this many distinct results: until then an
# ask that would use it (`gp`, or `portfolio` starting from it) proposes random feasible points, an initial design
# (BoTorch's and Ax's tutorials start from one, skopt from 10 points, Optuna from 10 trials). From one to four results
# the GP's expected improvement, with every small categorical option to be covered twice first, spent the early
# experiments on the conditions its few results made look least bad (m_coupling from the planner's first proposal, 24
# seeds: regret mean 0.098, worst 0.282; with hidden failures 0.205, worst 0.686); with the initial design 0.047 /
# 0.124 and 0.067 / 0.299 (benchmarks/README.md, round thirteen). The kernel density, Gryffin's model, proposes from
# the first result on.
GP_MIN_RESULTS = 5
# ... or until this many successful experiments, whatever their distinct results: an objective with fewer possible
# values (a rating of 0, 1 or 2; pass or fail) never reaches GP_MIN_RESULTS of them, and every proposal of such a
# campaign stayed random (3 continuous parameters, a 3-level rating: 24 of 24 asks). `portfolio` then proposes from
# the kernel density (`choose`): with a rating of 0/1/2 of 3 continuous conditions, 40 experiments, 24 seeds, the
# campaigns reached the top rating in 14 seeds that way, in 8 with the GP (benchmarks/README.md, round fourteen).
INITIAL_DESIGN_MAX = 2 * GP_MIN_RESULTS
# `portfolio` starts from the GP when the space has at least this many continuous parameters, from the kernel density
# otherwise. Measured (benchmarks/README.md, "Problem portfolio" and "Surrogates on the paper's surfaces"): the GP
# alone needs 4-5x more evaluations on the paper's 2-D plateau and rugged surfaces (Sphere, Michalewicz), where the
# kernel density first and the comparison keep the best of both; with 3+ continuous dims (the
# kinetics and smooth 6-D/10-D problems) the GP wins, and beyond 4 the kernel density keeps Gryffin's narrow kernels
# and is close to random search. With several objectives the portfolio keeps the kernel density: Chimera's merit
# steps at each tolerance, and a GP ranks such data well (so it takes over) but its expected improvement climbs the
# smoothed step slowly. Measured on the flow reactor (3 continuous, seeds 0-19, benchmarks/README.md "Applications"):
# GP first 0.0042 $/min, kernel density first with the GP taking over 0.0031 (seeds at 0.0065 and 0.0096 where it had;
# a trial tree), kernel density alone 0.0028 (worst 0.0037); on the redox candidates the GP did worse too.
PORTFOLIO_GP_MIN_CONTINUOUS = 3


class FitCache:
    """Fitted GP hyperparameters by the data they were fitted to (the fit is a pure function of its data, the
    campaign seed and the fit size, so a hit gives exactly what a new fit would: same proposals, no fit). Shared by
    a planner and the fresh planners of its stateless `recommend` calls, which see the same first observations
    again and again (a Gryffin 1.0 script's loop); the last MAX_ENTRIES fits are kept."""

    MAX_ENTRIES = 4

    def __init__(self) -> None:
        self._fits: OrderedDict[bytes, dict] = OrderedDict()

    @staticmethod
    def key(size: int, X: np.ndarray, y: np.ndarray, descriptors: Mapping[int, np.ndarray]) -> bytes:
        digest = hashlib.blake2b(str(size).encode(), digest_size=20)
        for array in (X, y, *(np.asarray(descriptors[d]) for d in sorted(descriptors))):
            array = np.ascontiguousarray(array, dtype=float)
            digest.update(str(array.shape).encode())
            digest.update(array.tobytes())
        return digest.digest()

    def get(self, key: bytes) -> dict | None:
        fit = self._fits.get(key)
        if fit is not None:
            self._fits.move_to_end(key)
        return fit

    def put(self, key: bytes, hyperparameters: dict) -> None:
        self._fits[key] = hyperparameters
        self._fits.move_to_end(key)
        while len(self._fits) > self.MAX_ENTRIES:
            self._fits.popitem(last=False)


class SurrogateChoice:
    """Chooses the surrogate of each ask. `raw_merits(observations)` gives the untransformed merits of successful
    observations (what the GP regresses: a square root would put a cusp at the optimum)."""

    def __init__(self, setting: str, space: SearchSpace, seed: int,
                 raw_merits: Callable[[Sequence[Observation]], np.ndarray], objectives: int = 1):
        if setting not in SURROGATES:
            raise ValueError(f"unknown surrogate {setting!r}; choose one of {SURROGATES}")
        self.setting, self.space, self.seed, self.raw_merits = setting, space, seed, raw_merits
        self.objectives = objectives
        self.fits = FitCache()  # a fresh planner of a stateless recommend shares its parent's
        if setting != "kde":
            from .gaussian_process import require_botorch
            require_botorch()

    def gaussian_process(self, X: np.ndarray, successful: Sequence[Observation],
                         descriptors: Mapping[int, np.ndarray]) -> GaussianProcess:
        """The GP of the untransformed merits, conditioned on every successful experiment (at most COND_MAX of them,
        `condition_subset`), with hyperparameters fitted to the first `fit_size(n)` of them (at most FIT_MAX of those,
        `fit_subset`) with their merits among themselves: a fit depends on those first observations alone (learned
        descriptors change with every observation, so with them every ask fits), and is looked up in `fits` before
        it is made. Fits and subsets are seeded by the campaign seed and their size alone, so they never change the
        draws of the rest of the ask."""
        from .gaussian_process import FIT_MAX, GaussianProcess, condition_subset, fit_size, fit_subset

        def seed(size: int) -> int:
            return int(np.random.default_rng([self.seed, size, 3]).integers(2**62))

        size = len(X) if descriptors else fit_size(len(X))
        y = self.raw_merits(successful)
        # several objectives: Chimera's merits depend on every observation's range, so the first `size` are
        # ranked among themselves (one objective: the same values)
        y_fit = y if size == len(X) else self.raw_merits(successful[:size])
        key = self.fits.key(size, X[:size], y_fit, descriptors)
        hyperparameters = self.fits.get(key)
        if hyperparameters is None and (size < len(X) or size > FIT_MAX):
            subset = fit_subset(y_fit, seed(size))
            hyperparameters = GaussianProcess(self.space, X[subset], y_fit[subset], seed(size), descriptors
                                              ).hyperparameters
        # above COND_MAX observations, conditioned on a subset (there size > FIT_MAX: hyperparameters are given)
        kept = condition_subset(y, int(np.random.default_rng([self.seed, len(X), 4]).integers(2**62)))
        gp = GaussianProcess(self.space, X[kept], y[kept], seed(size), descriptors, hyperparameters)
        gp.conditioned = kept
        self.fits.put(key, gp.hyperparameters)
        return gp

    def local_gaussian_process(self, X: np.ndarray, successful: Sequence[Observation],
                               descriptors: Mapping[int, np.ndarray], rows: np.ndarray) -> GaussianProcess:
        """The GP of the untransformed merits of the successful experiments `rows` (a boolean mask) alone: one
        combination of options (`strategies.gryffin`, where the ask runs it), its hyperparameters fitted to those
        experiments, seeded by the campaign seed and the number of successful experiments. Fitted and conditioned on
        FIT_MAX of them at most (`fit_subset`: the best and a seeded draw of the rest), so a long campaign on few
        combinations does not pay n^3 for it."""
        from .gaussian_process import GaussianProcess, fit_subset

        y = self.raw_merits(successful)
        seed = int(np.random.default_rng([self.seed, len(X), 5]).integers(2**62))
        index = np.flatnonzero(rows)
        index = index[fit_subset(y[index], seed)]
        return GaussianProcess(self.space, X[index], y[index], seed, descriptors)

    def initial_design(self, levels: int, successes: int) -> bool:
        """Whether an ask's proposals are random feasible points (`GP_MIN_RESULTS`): the GP would make them (`gp`, or
        `portfolio` starting from it) and the `successes` successful experiments, fewer than INITIAL_DESIGN_MAX, have
        `levels` < GP_MIN_RESULTS distinct results."""
        from_gp = self.setting == "gp" or (self.setting == "portfolio" and self.objectives == 1
                                           and self.prior() == "gp")
        return from_gp and levels < GP_MIN_RESULTS and successes < INITIAL_DESIGN_MAX

    def prior(self) -> str:
        """The model of `auto`/`portfolio` until the data clearly favour the other one."""
        if self.setting == "portfolio" and len(self.space.cont_idx) >= PORTFOLIO_GP_MIN_CONTINUOUS:
            return "gp"
        return "kde"

    def choose(self, X: np.ndarray, merits: np.ndarray, successful: Sequence[Observation], density: KernelDensity,
               descriptors: Mapping[int, np.ndarray]) -> tuple[GaussianProcess | None, dict[str, Any]]:
        """The GP (or None for the kernel density) and what the proposals record about the choice.

        `auto` and `portfolio` compare the two models on the data so far by the rank correlation of their
        leave-one-out predictions with the observed merits (what the acquisition needs is the ordering of points, not
        calibrated values). The other model replaces the prior one (`prior()`) only when it ranks better by more than
        the sampling error of the score (Fisher z of Spearman's r, s.e. sqrt(1.06 / (m - 3))), m the number of
        distinct merits: tied results carry no ranking, so on plateaus (a step-shaped surface with a few levels) the
        score says little and the prior model stays; never with fewer than AUTO_MIN_OBSERVATIONS distinct merits.
        With fewer than that, `portfolio` proposes from the kernel density even where the GP comes first: its initial
        design (`initial_design`) has then ended after INITIAL_DESIGN_MAX successful experiments, so the results take
        few values (a rating), where the kernel density did better."""
        if self.setting == "kde":
            return None, {"surrogate": "kde"}
        if self.setting == "gp":
            return self.gaussian_process(X, successful, descriptors), {"surrogate": "gp"}
        if self.setting == "portfolio" and self.objectives > 1:
            return None, {"surrogate": "kde", "surrogate_reason": f"portfolio: {self.objectives} objectives: the "
                          "kernel density (Chimera's merit steps at each tolerance)"}
        prior = self.prior()
        shape = (f"{self.setting}: {len(self.space.cont_idx)} continuous parameter(s), "
                 f"{'GP' if prior == 'gp' else 'kernel density'} first")
        levels = len(np.unique(merits))
        if levels < AUTO_MIN_OBSERVATIONS:
            if prior == "gp":  # (portfolio) its initial design ended at INITIAL_DESIGN_MAX successful experiments
                return None, {"surrogate": "kde", "surrogate_reason": f"{shape}; {levels} distinct results in "
                              f"{len(merits)} successful experiments: a result with few values, the kernel density"}
            return None, {"surrogate": "kde", "surrogate_reason": f"{shape}; fewer than {AUTO_MIN_OBSERVATIONS} "
                          "distinct successful results to compare the models on"}
        from .gaussian_process import rank_correlation
        gp = self.gaussian_process(X, successful, descriptors)
        kept = gp.conditioned  # both models are scored on the observations the GP is conditioned on
        levels = len(np.unique(merits[kept]))
        if levels < AUTO_MIN_OBSERVATIONS:
            return (gp if prior == "gp" else None), {
                "surrogate": prior, "surrogate_reason": f"{shape}; fewer than {AUTO_MIN_OBSERVATIONS} distinct "
                "successful results among those the GP is conditioned on to compare the models on"}
        scores = {"kde": round(rank_correlation(density.leave_one_out(kept), merits[kept]), 4),
                  "gp": round(rank_correlation(gp.leave_one_out(), merits[kept]), 4)}
        z = {name: math.atanh(min(max(r, -0.999), 0.999)) for name, r in scores.items()}
        other = "kde" if prior == "gp" else "gp"
        margin = math.sqrt(1.06 / (levels - 3))
        chosen = other if z[other] - z[prior] > margin else prior
        verdict = ("clearly better" if chosen == other else "not clearly better")
        reason = (f"{shape}; {'GP' if other == 'gp' else 'kernel density'} {verdict} on held-out ranking "
                  f"(Spearman {scores[other]} vs {scores[prior]}, {levels} distinct results)")
        return (gp if chosen == "gp" else None), {"surrogate": chosen, "surrogate_reason": reason,
                                                  "loo_rank_correlation": scores}
