"""The Gaussian-process surrogate (general.surrogate = gp), built on BoTorch/GPyTorch: an exact GP with a Matern-5/2
ARD kernel on normalized inputs, standardized outputs and hyperparameters by marginal likelihood, and its log expected
improvement as an acquisition (`acquisition.gp.GPAcquisition`) that the planner's constrained optimizers (Adam/Hill,
genetic) minimize like Gryffin's.

Inputs: continuous dims as they are inside the planner ([0, 1]; periodic ones as a point on a circle), discrete dims
at their ordinal positions in [0, 1], categorical dims through their descriptors (static or learned, each column
scaled to [0, 1]) or, without descriptors, as categories (BoTorch's mixed categorical kernel). With two or more
categorical parameters with descriptors the kernel is a sum of such Matern kernels: one over every input and one per
parameter for its main effect (`main_effects_kernel`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from functools import partial

import numpy as np
import torch

from ..errors import ConfigError
from ..space import SearchSpace
from .kernel_density import split

DTYPE = torch.float64
# Noise floor (variance, standardized units): low enough that a noiseless objective is interpolated closely near its
# optimum, where regrets of 1e-3 of the range are asked for; GPyTorch's default floor (1e-4) blurs that.
MIN_NOISE = 1e-6
# Kernel length scales (inputs in [0, 1]) and output scale (outputs standardized) are fitted within these bounds.
LENGTHSCALE_BOUNDS = (1e-3, 20.0)
OUTPUTSCALE_BOUNDS = (1e-3, 100.0)
# ... except on the descriptor columns of categorical parameters (each scaled to [0, 1]), whose length scales stay at
# or above DESCRIPTOR_LENGTHSCALE_MIN: far below the spacing of the options, every option (and every combination of
# options) is its own unrelated function and the descriptors tell the GP nothing. m_coupling's fits (3 categorical
# parameters with descriptors, 3 continuous) ended at 0.001-0.02 there, and their expected improvement beside the
# first good combination always beat that of the untried ones (seed 8 stayed on its first one for 30 experiments,
# normalized regret 0.55; benchmarks/README.md "Stuck campaigns on mixed spaces"). At 0.2, options a quarter of the
# range apart still correlate at ~0.4 (Matern-5/2).
DESCRIPTOR_LENGTHSCALE_MIN = 0.2
# The length scales of continuous inputs and of descriptor columns have BoTorch's default prior (Hvarfner, Hellsten &
# Nardi 2024, "Vanilla Bayesian optimization performs great in high dimensions"): log-normal with location
# sqrt(2) + log(d) / 2 and scale sqrt(3), d the number of the kernel's inputs, wide enough for the data to override.
# With the marginal likelihood alone, m_coupling's fits (seed 14, 20 to 32 results) put the temperature's length
# scale at 0.004 and those of time and loading at the bound 20: every temperature its own function, time and loading
# irrelevant. Its expected improvement then kept 14 of the last 16 experiments at the incumbent's temperature and
# crawled along time and loading. With the prior the same data give 1.1, 0.95 and 0.35-0.48; on 12 seeds of each
# mixed task mean and worst regret fell (benchmarks/README.md "Stuck campaigns on mixed spaces", round seven).
# A discrete parameter's ordinal positions have no prior: there it cost the paper's Michalewicz with unknown
# constraints 21.7 -> 24.9 evaluations (30 seeds).
LENGTHSCALE_PRIOR_LOC, LENGTHSCALE_PRIOR_SCALE = math.sqrt(2.0), math.sqrt(3.0)
# A length scale drawn from that prior beyond its bounds is set this share of the bounds' span inside them
# (`set_lengthscales_of`): exactly at a bound the constraint's inverse transform is infinite.
PRIOR_DRAW_MARGIN = 1e-6
# Largest number of candidates in one posterior evaluation.
CHUNK = 4096
# Hyperparameters are fitted to at most FIT_MAX observations (each marginal-likelihood evaluation costs n^3: a fit took
# 7 s at n = 1000, d = 10): the best FIT_BEST of them by merit, where the acquisition works, and an even random draw
# of the rest. The GP is then conditioned with those hyperparameters on every observation, up to COND_MAX.
FIT_MAX, FIT_BEST = 300, 100
# Above COND_MAX observations the GP is conditioned on COND_MAX of them: the COND_BEST best by merit (the incumbent
# and where the acquisition works) and a seeded random draw of the rest, new each ask. Exact conditioning costs n^3
# for the Cholesky factor and (M, n) per candidate batch: a warm ask took 9.5 s at n = 5000 on 2 cores. Without known
# constraints (Adam then runs all its steps) a warm ask at n = 1000, d = 10 took 0.89-0.92 s conditioned on all
# 1000, 0.55-0.60 s on 700 and 0.33-0.42 s on 500; over 9 seeds the values of the next 10 proposals were the same
# on 700 as on 1000 (best -5.08 and -5.08, mean -4.46 and -4.50), worse on 500 (-4.80, -4.39). benchmarks/README.md,
# "Lab-scale ask times", round three.
COND_MAX, COND_BEST = 700, 300
# The marginal likelihood has a second optimum that explains the data as noise around a constant (output scale at its
# floor, long length scales); fits from BoTorch's start (the middle of the bounds: length scales 10, output scale 50)
# ended there on 8 random points of a smooth 3-D bowl and on m_coupling's seed 2 after 15 and 25 results, and such a
# GP's expected improvement never left the first good combination of categories (benchmarks/README.md, "Stuck
# campaigns on mixed spaces"). A fit whose kernel variance is below MIN_SIGNAL_TO_NOISE times its noise variance is
# repeated from SHORT_START (length scales, output scale, noise; standardized units); the more likely one is kept.
# Collapsed fits have a ratio of ~0.002 (the paper's Sphere with unknown constraints) to < 0.01 (the bowl above); the
# flow reactor's noisy fits have ~0.6, and repeating those (threshold 1) left 6 of 20 campaigns on a poor cost.
MIN_SIGNAL_TO_NOISE = 0.1
SHORT_START = (0.3, 1.0, 1e-3)
# With two or more categorical parameters with descriptors, the kernel is the sum of one ARD Matern over every input
# (every interaction) and, for each such parameter, one over that parameter's descriptor columns and the inputs that
# are not a categorical parameter's descriptors (its main effect: how good a ligand is, with whatever base and solvent,
# as conditions vary). One product kernel learns little about an untried combination from its options' results with
# other partners: m_coupling (ligand, base, solvent + 3 conditions, harness start, 48 seeds) mean regret 0.064 ->
# 0.039, worst seed 0.397 -> 0.097 (seed 16 settled on a combination and ended at 0.34, the optimum being 0.74); from
# the planner's first proposal (24 seeds) 0.047 -> 0.034 (benchmarks/README.md "Stuck campaigns on mixed spaces",
# round nineteen).
MAIN_EFFECTS_MIN_PARAMETERS = 2

try:
    from botorch.exceptions import ModelFittingError
    from botorch.fit import fit_gpytorch_mll
    from botorch.models import MixedSingleTaskGP, SingleTaskGP
    from botorch.models.transforms.outcome import Standardize
    from botorch.models.utils.gpytorch_modules import (
        get_gaussian_likelihood_with_lognormal_prior,
    )
    from gpytorch.constraints import GreaterThan, Interval
    from gpytorch.kernels import AdditiveKernel, MaternKernel, ScaleKernel
    from gpytorch.mlls import ExactMarginalLogLikelihood
    from gpytorch.priors import LogNormalPrior
except ImportError as _error:  # a dependency of the package; a broken install is reported when a GP is first needed
    _IMPORT_ERROR: ImportError | None = _error
else:
    _IMPORT_ERROR = None


def require_botorch() -> None:
    """Raise a ConfigError that says how to install the GP's libraries when they are missing."""
    if _IMPORT_ERROR is not None:
        raise ConfigError(f"general.surrogate 'portfolio' (the default), 'gp' and 'auto' need BoTorch, which could "
                          f"not be imported (pip install 'botorch>=0.12', or general.surrogate: kde): {_IMPORT_ERROR}")


class Features:
    """Planner points (M, D) -> GP inputs (M, G) in [0, 1], differentiable in the continuous coordinates."""

    def __init__(self, space: SearchSpace, descriptors: Mapping[int, np.ndarray] | None = None):
        self.space = space
        self.columns: list[tuple[str, int, torch.Tensor | None]] = []  # (kind, position in xc/xf, lookup table)
        for j, d in enumerate(space.cont_idx):
            self.columns.append(("periodic" if space.periodic[d] else "continuous", j, None))
        for j, d in enumerate(space.finite_idx):
            table = (descriptors or {}).get(int(d), space.descriptors(int(d)))
            if table is None:
                self.columns.append(("category", j, None))
                continue
            table = np.asarray(table, dtype=float)
            span = table.max(axis=0) - table.min(axis=0)
            useful = span > 0
            if not useful.any():  # descriptors that cannot tell the options apart: the options themselves
                self.columns.append(("category", j, None))
                continue
            scaled = (table[:, useful] - table.min(axis=0)[useful]) / span[useful]
            self.columns.append(("table", j, torch.as_tensor(scaled, dtype=DTYPE)))
        parts = [1 if kind in ("continuous", "category") else (2 if kind == "periodic" else len(table.T))
                 for kind, _, table in self.columns]
        offsets = np.cumsum([0] + parts)
        self.dim = int(offsets[-1])
        self.cat_dims = [int(offsets[i]) for i, (kind, _, _) in enumerate(self.columns) if kind == "category"]
        # the least length scale of each input that a Matern kernel sees (all but the categorical ones), in order,
        # which of those inputs have the length-scale prior (all but a discrete parameter's ordinal positions), and
        # the inputs of each categorical parameter with descriptors, one list per parameter (`main_effects_kernel`)
        floors, prior, self.described_groups = [], [], []
        for (kind, j, _), width, offset in zip(self.columns, parts, offsets):
            if kind != "category":
                described = kind == "table" and space.parameters[int(space.finite_idx[j])].kind == "categorical"
                floors += [DESCRIPTOR_LENGTHSCALE_MIN if described else LENGTHSCALE_BOUNDS[0]] * width
                prior += [kind != "table" or described] * width
                if described:
                    self.described_groups.append(list(range(int(offset), int(offset) + width)))
        self.lengthscale_floors = torch.as_tensor(floors, dtype=DTYPE)
        self.prior_inputs = [i for i, p in enumerate(prior) if p]

    def __call__(self, xc: torch.Tensor, xf: torch.Tensor) -> torch.Tensor:
        """xc: (M, C) continuous coordinates (may require grad), xf: (M, F) long option indices -> (M, G)."""
        out = []
        for kind, j, table in self.columns:
            if kind == "continuous":
                out.append(xc[:, j:j + 1])
            elif kind == "periodic":
                angle = 2 * math.pi * xc[:, j:j + 1]
                out += [0.5 + 0.5 * torch.sin(angle), 0.5 + 0.5 * torch.cos(angle)]
            elif kind == "category":
                out.append(xf[:, j:j + 1].to(DTYPE))
            else:
                out.append(table[xf[:, j]])
        return torch.cat(out, dim=1)

    def of(self, X: np.ndarray) -> torch.Tensor:
        """(M, D) internal points -> (M, G) inputs."""
        return self(*split(self.space, X))


def best_and_drawn(y: np.ndarray, seed: int, size: int, best: int) -> np.ndarray:
    """Indices of at most `size` observations (merits y, minimized): all of them up to `size`, else the `best` best
    and a seeded random draw of the others, in their original order."""
    n = len(y)
    if n <= size:
        return np.arange(n)
    top = np.argsort(y, kind="stable")[:best]
    rest = np.setdiff1d(np.arange(n), top)
    drawn = np.random.default_rng(seed).choice(rest, size - best, replace=False)
    return np.sort(np.concatenate([top, drawn]))


def fit_subset(y: np.ndarray, seed: int) -> np.ndarray:
    """The observations hyperparameters are fitted to (FIT_MAX of them at most)."""
    return best_and_drawn(y, seed, FIT_MAX, FIT_BEST)


def condition_subset(y: np.ndarray, seed: int) -> np.ndarray:
    """The observations the GP is conditioned on (COND_MAX of them at most)."""
    return best_and_drawn(y, seed, COND_MAX, COND_BEST)


def fit_size(n: int) -> int:
    """How many of the first n observations the hyperparameters are fitted to: all of them up to 19, then the
    largest multiple of n // 10 (a refit every 2nd observation at 20, every 10th at 100). In between, the GP keeps
    the last fit's hyperparameters and is conditioned on all the data; a fit is the costly part of an ask, and a
    restarted planner refits exactly the same hyperparameters from the same first observations."""
    step = max(1, n // 10)
    return n - n % step


class GaussianProcess:
    """An exact GP fitted to (X, y), y minimized: hyperparameters by marginal likelihood (seeded random restarts,
    if BoTorch needs any), or given (`hyperparameters` of an earlier fit to part of the same campaign)."""

    def __init__(self, space: SearchSpace, X: np.ndarray, y: np.ndarray, seed: int,
                 descriptors: Mapping[int, np.ndarray] | None = None,
                 hyperparameters: Mapping[str, torch.Tensor] | None = None):
        require_botorch()
        self.space = space
        self.features = Features(space, descriptors)
        train_X = self.features.of(X).detach()
        train_Y = torch.as_tensor(np.asarray(y, dtype=float)[:, None], dtype=DTYPE)
        likelihood = get_gaussian_likelihood_with_lognormal_prior()
        likelihood.noise_covar.register_constraint("raw_noise", GreaterThan(MIN_NOISE))
        # ARD Matern-5/2 with the length-scale prior above, within bounds that keep a smooth trend (a quadratic bowl, a
        # slope) from pushing length and output scales to infinity
        floors = self.features.lengthscale_floors
        # per input; with categorical options only (no descriptors) no Matern kernel is made, and gpytorch refuses
        # an Interval of empty bounds
        bounds = (Interval(floors, torch.full_like(floors, LENGTHSCALE_BOUNDS[1])) if len(floors)
                  else Interval(*LENGTHSCALE_BOUNDS))
        matern = partial(matern_kernel, bounds, self.features.prior_inputs)
        if self.features.cat_dims:
            self.model = MixedSingleTaskGP(train_X, train_Y, cat_dims=self.features.cat_dims, likelihood=likelihood,
                                           cont_kernel_factory=matern, outcome_transform=Standardize(m=1))
        else:
            if len(self.features.described_groups) >= MAIN_EFFECTS_MIN_PARAMETERS:
                covar = main_effects_kernel(self.features)
            else:
                covar = ScaleKernel(matern(ard_num_dims=self.features.dim),
                                    outputscale_constraint=Interval(*OUTPUTSCALE_BOUNDS))
            self.model = SingleTaskGP(train_X, train_Y, likelihood=likelihood, covar_module=covar,
                                      outcome_transform=Standardize(m=1))
        if hyperparameters is not None:
            self.model.load_state_dict(dict(hyperparameters), strict=False)
        else:
            with torch.random.fork_rng(), warnings.catch_warnings():
                torch.manual_seed(seed)
                warnings.simplefilter("ignore")  # BoTorch's notes on fit retries and input scaling: handled here
                self._fit()
                if self.signal_to_noise() < MIN_SIGNAL_TO_NOISE:
                    collapsed, likelihood_of_collapsed = self.hyperparameters, self.log_likelihood()
                    short_start(self.model)
                    self._fit()
                    if self.log_likelihood() < likelihood_of_collapsed:
                        self.model.load_state_dict(collapsed, strict=False)
        self.model.eval()
        self._posterior: Posterior | None = None
        # indices of the campaign's observations (X, y) are of; its maker sets them when X is a subset
        self.conditioned = np.arange(len(X))

    def _fit(self) -> None:
        """Hyperparameters by marginal likelihood from the model's current ones."""
        initial = self.hyperparameters
        try:
            fit_gpytorch_mll(ExactMarginalLogLikelihood(self.model.likelihood, self.model))
        except ModelFittingError:
            # no attempt converged; the last one's point is kept when it is a usable model, else the start
            if not all(torch.isfinite(v).all() for v in self.hyperparameters.values()):
                self.model.load_state_dict(initial, strict=False)

    def log_likelihood(self) -> float:
        """The marginal log likelihood (per observation, with the noise prior) of the current hyperparameters."""
        self.model.train()
        with torch.no_grad():
            value = ExactMarginalLogLikelihood(self.model.likelihood, self.model)(
                self.model(*self.model.train_inputs), self.model.train_targets).item()
        self.model.eval()
        return value

    def signal_to_noise(self) -> float:
        """The kernel's prior variance at the training inputs (mean) over the noise variance."""
        with torch.no_grad():
            signal = self.model.covar_module(*self.model.train_inputs, diag=True).mean()
            return float(signal / self.model.likelihood.noise.reshape(()))

    @property
    def hyperparameters(self) -> dict[str, torch.Tensor]:
        """Kernel, noise and mean parameters (not the output standardization, which belongs to the data)."""
        return {k: v.detach().clone() for k, v in self.model.state_dict().items()
                if not k.startswith("outcome_transform")}

    def leave_one_out(self) -> np.ndarray:
        """(n,) leave-one-out predictive means of the training targets, with the fitted hyperparameters
        (Rasmussen & Williams eq. 5.12), in standardized units. The posterior's Cholesky factor serves: its leading
        n x n block is that of the training covariance, whatever points were believed after it."""
        post, n = self.posterior, len(self.model.train_targets)
        with torch.no_grad():
            y, X = post.y[:n], post.X[:n]
            K_inv = torch.cholesky_inverse(post.L[:n, :n])
            alpha = K_inv @ (y - post.mean(X))
            return (y - alpha / torch.diagonal(K_inv)).numpy()

    def at_results_mean(self) -> None:
        """Put the prior mean at the mean of the results (0 in standardized units) instead of its fitted constant,
        which sits on the plateau where most results lie when most are poor: untried regions are then predicted at
        the average result (`strategies.stall`). Before any point is believed."""
        with torch.no_grad():
            self.model.mean_module.constant = torch.zeros_like(self.model.mean_module.constant)
        self._posterior = None

    def believe(self, X: np.ndarray, incumbent: bool = True) -> None:
        """Kriging believer: condition the GP on its own posterior mean at points whose results are not known yet
        (pending experiments, earlier proposals of this batch), so they are not proposed again. `incumbent=False` for
        points that will never have a result (failed experiments): each is believed at its posterior mean or at the
        incumbent, whichever is worse (a failed experiment improved on nothing), and never becomes the incumbent."""
        if len(X):
            self.posterior.believe(self.features.of(X), incumbent)

    @property
    def posterior(self) -> Posterior:
        if self._posterior is None:
            self._posterior = Posterior(self.model)
        return self._posterior


def matern_kernel(bounds, prior_inputs: list[int], ard_num_dims: int, batch_shape: torch.Size | None = None,
                  active_dims: list[int] | None = None) -> MaternKernel:
    """An ARD Matern-5/2 kernel on `ard_num_dims` inputs, its length scales within `bounds`, those of the inputs
    `prior_inputs` under the log-normal prior (LENGTHSCALE_PRIOR_LOC + log(ard_num_dims) / 2, LENGTHSCALE_PRIOR_SCALE);
    BoTorch's MixedSingleTaskGP calls it with the batch shape and the active (non-categorical) inputs."""
    kernel = MaternKernel(nu=2.5, ard_num_dims=ard_num_dims, batch_shape=batch_shape, active_dims=active_dims,
                          lengthscale_constraint=bounds)
    if prior_inputs:
        prior = LogNormalPrior(LENGTHSCALE_PRIOR_LOC + 0.5 * math.log(ard_num_dims), LENGTHSCALE_PRIOR_SCALE)
        kernel.register_prior("lengthscale_prior", prior, partial(lengthscales_of, prior_inputs),
                              partial(set_lengthscales_of, prior_inputs))
    return kernel


def main_effects_kernel(features: Features) -> AdditiveKernel:
    """Every interaction (a scaled ARD Matern over every input) plus, for each categorical parameter with descriptors
    (`features.described_groups`), a scaled ARD Matern over its descriptor columns and the inputs outside every such
    group: the parameter's main effect, shared by every combination of the other categorical parameters
    (MAIN_EFFECTS_MIN_PARAMETERS). Each term keeps the inputs' length-scale floors, bounds and prior; for spaces
    without category inputs (every input has a floor)."""
    groups = features.described_groups
    described = {i for g in groups for i in g}
    rest = [i for i in range(features.dim) if i not in described]
    floors = features.lengthscale_floors
    prior = set(features.prior_inputs)

    def component(inputs: list[int]) -> ScaleKernel:
        f = floors[inputs]
        kernel = matern_kernel(Interval(f, torch.full_like(f, LENGTHSCALE_BOUNDS[1])),
                               [k for k, i in enumerate(inputs) if i in prior], len(inputs), active_dims=inputs)
        return ScaleKernel(kernel, outputscale_constraint=Interval(*OUTPUTSCALE_BOUNDS))

    return AdditiveKernel(component(list(range(features.dim))), *(component(sorted(rest + g)) for g in groups))


def lengthscales_of(inputs: list[int], kernel: MaternKernel) -> torch.Tensor:
    """The length scales of some of a kernel's inputs (what its prior sees)."""
    return kernel.lengthscale[..., inputs]


def set_lengthscales_of(inputs: list[int], kernel: MaternKernel, value: torch.Tensor) -> None:
    """Set the length scales of some of a kernel's inputs, the others kept: BoTorch's fit, when no attempt converges,
    retries from length scales drawn from the prior (`sample_all_priors`), which sets them through this. A drawn value
    beyond the bounds is taken just inside them: raising GPyTorch's out-of-bounds error made BoTorch draw every length
    scale again, up to 100 times, and then fail the ask, and with the prior's median near the upper bound a draw of
    eight or more inputs all within it is rare ("Failed to sample a feasible parameter value from the prior after 100
    attempts" in 7 of 11 m_electrochem campaigns with round thirty's main-effect terms, kernels over six and nine
    inputs; benchmarks/README.md)."""
    lengthscale = kernel.lengthscale.detach().clone()
    constraint = kernel.raw_lengthscale_constraint
    low = constraint.lower_bound.to(lengthscale).expand_as(lengthscale)[..., inputs]
    high = constraint.upper_bound.to(lengthscale).expand_as(lengthscale)[..., inputs]
    margin = PRIOR_DRAW_MARGIN * (high - low)
    lengthscale[..., inputs] = torch.minimum(torch.maximum(value.to(lengthscale), low + margin), high - margin)
    kernel.lengthscale = lengthscale


def short_start(model) -> None:
    """Set the kernels' length scales, output scales and the noise of `model` to SHORT_START."""
    lengthscale, outputscale, noise = SHORT_START
    for module in model.covar_module.modules():
        if isinstance(module, ScaleKernel):
            module.outputscale = outputscale
        elif getattr(module, "has_lengthscale", False):
            module.lengthscale = lengthscale
    model.likelihood.noise = noise


class Posterior:
    """The fitted GP's posterior in standardized output units, computed from one kernel matrix between candidates
    and training inputs (M, n) and the Cholesky factor of the training covariance, which kriging-believer points
    extend block by block (exact, O(n^2) per point). GPyTorch's own path evaluates a batch of M single-point
    posteriors and copies the training inputs once per candidate: 1.1 s for 4000 candidates at n = 1000, d = 10."""

    def __init__(self, model):
        self.kernel, self.mean = model.covar_module, model.mean_module
        self.noise = model.likelihood.noise.detach().reshape(()).item()
        with torch.no_grad():
            self.X = model.train_inputs[0].detach()
            self.y = model.train_targets.detach()
            self.best = float(self.y.min())  # the incumbent: the best merit, observed or believed
            # every kernel here is stationary (Matern on distances, BoTorch's categorical kernel on equality), so
            # the prior variance k(z, z) is the same at every input; GPyTorch's diagonal of the categorical kernel
            # builds the whole (M, M) matrix first (0.5 s of a 1 s mixed ask at 16 observations)
            self.prior_variance = self.kernel(self.X[:1], self.X[:1], diag=True).reshape(())
            K = self.kernel(self.X).to_dense() + self.noise * torch.eye(len(self.X), dtype=DTYPE)
            self.L = torch.linalg.cholesky(K)
            self._update_weights()

    def _update_weights(self) -> None:
        with torch.no_grad():
            residual = (self.y - self.mean(self.X))[:, None]
            self.weights = torch.cholesky_solve(residual, self.L)[:, 0]

    def mean_and_sigma(self, Z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Posterior mean and standard deviation at inputs Z (M, G), differentiable in Z."""
        cross = self.kernel(Z, self.X).to_dense()  # (M, n)
        mean = self.mean(Z) + cross @ self.weights
        v = torch.linalg.solve_triangular(self.L, cross.T, upper=False)  # (n, M)
        return mean, (self.prior_variance - (v ** 2).sum(0)).clamp_min(1e-12).sqrt()

    def believe(self, Z: torch.Tensor, incumbent: bool = True) -> None:
        """Add inputs Z (B, G) as observations at their posterior mean, which may become the incumbent; with
        `incumbent=False` at the posterior mean or the incumbent, whichever is worse."""
        with torch.no_grad():
            for z in Z:
                z = z[None]
                cross = self.kernel(z, self.X).to_dense()  # (1, n)
                mean = self.mean(z) + cross @ self.weights
                if not incumbent:
                    # a failed experiment: believed at its mean, the GP extrapolated the feasible results' trend into a
                    # failing region (the unconstrained optimum inside it) and the expected improvement between the
                    # failures stayed best - mean > 0 (benchmarks/README.md, round eight)
                    mean = mean.clamp_min(self.best)
                row = torch.linalg.solve_triangular(self.L, cross.T, upper=False)  # (n, 1): the new row of L
                corner = (self.prior_variance[None] + self.noise - (row ** 2).sum()).clamp_min(1e-12).sqrt()
                n = len(self.X)
                L = torch.zeros((n + 1, n + 1), dtype=DTYPE)
                L[:n, :n], L[n, :n], L[n, n] = self.L, row[:, 0], corner[0]
                self.L, self.X, self.y = L, torch.cat([self.X, z]), torch.cat([self.y, mean])
                # a believed result below the incumbent becomes the incumbent (kriging believer): else the expected
                # improvement next to it stays best - mean > 0 however small the variance, and a batch piles up there
                if incumbent:
                    self.best = min(self.best, float(mean))
                self._update_weights()


def rank_correlation(a: np.ndarray, b: np.ndarray) -> float:
    """Spearman's rank correlation (average ranks for ties); 0 when either side is constant."""
    def ranks(v: np.ndarray) -> np.ndarray:
        order = np.argsort(v, kind="stable")
        r = np.empty(len(v))
        r[order] = np.arange(len(v), dtype=float)
        _, group = np.unique(v, return_inverse=True)
        return (np.bincount(group, weights=r) / np.bincount(group))[group]

    ra, rb = ranks(np.asarray(a, dtype=float)), ranks(np.asarray(b, dtype=float))
    ra, rb = ra - ra.mean(), rb - rb.mean()
    denominator = math.sqrt(float((ra ** 2).sum() * (rb ** 2).sum()))
    return float((ra * rb).sum() / denominator) if denominator > 0 else 0.0
