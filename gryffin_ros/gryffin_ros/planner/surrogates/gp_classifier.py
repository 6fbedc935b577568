"""A Gaussian-process classifier of feasibility (general.feas_model = gp), as Atlas models unknown constraints: a
variational GP with a Bernoulli likelihood and its own ARD Matern-5/2 length scales, all inference by GPyTorch.

Inputs are those of the GP surrogate (`gaussian_process.Features`), categories without descriptors one-hot encoded.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from functools import partial

import numpy as np
import torch

from ..errors import GryffinRosError
from ..space import SearchSpace
from .gaussian_process import DTYPE, Features, require_botorch

# ELBO steps of Adam (learning rate FIT_LR) from the prior, ~1 s per fit of 40 labels. Larger rates (0.1, 0.2 over
# 100 and 60 steps) settled on long length scales and a nearly constant P on a failing corner of a 2-d grid.
FIT_STEPS, FIT_LR = 150, 0.05
# Length scales (inputs in [0, 1]): a Gamma(3, 6) prior (BoTorch's former default, mode 1/3) keeps a handful of
# labels from collapsing them onto single points; bounded below by about half a grid cell of a 21-option parameter.
LENGTHSCALE_PRIOR = (3.0, 6.0)
LENGTHSCALE_MIN = 0.02
# At most this many inducing points (a seeded draw of the observations above it): the variational fit costs m^3.
MAX_INDUCING = 200

try:
    import gpytorch
    from botorch.optim.closures import ForwardBackwardClosure
    from botorch.optim.fit import fit_gpytorch_mll_torch
    from gpytorch.constraints import GreaterThan
    from gpytorch.distributions import MultivariateNormal
    from gpytorch.kernels import MaternKernel, ScaleKernel
    from gpytorch.likelihoods import BernoulliLikelihood
    from gpytorch.means import ConstantMean
    from gpytorch.mlls import VariationalELBO
    from gpytorch.models import ApproximateGP
    from gpytorch.priors import GammaPrior
    from gpytorch.variational import CholeskyVariationalDistribution, VariationalStrategy
except ImportError:  # require_botorch() reports it when the classifier is first needed
    ApproximateGP = object


class ClassifierFitError(GryffinRosError):
    """The GP classifier of feasibility could not be fitted (the planner falls back to the kernel-density model)."""


class _VariationalClassifier(ApproximateGP):
    def __init__(self, inducing: torch.Tensor):
        strategy = VariationalStrategy(self, inducing, CholeskyVariationalDistribution(inducing.shape[0]),
                                       learn_inducing_locations=False)
        super().__init__(strategy)
        self.mean_module = ConstantMean()
        self.covar_module = ScaleKernel(MaternKernel(
            nu=2.5, ard_num_dims=inducing.shape[1], lengthscale_prior=GammaPrior(*LENGTHSCALE_PRIOR),
            lengthscale_constraint=GreaterThan(LENGTHSCALE_MIN)))

    def forward(self, x: torch.Tensor) -> MultivariateNormal:
        return MultivariateNormal(self.mean_module(x), self.covar_module(x))


class GPClassifier:
    """P(feasible | x) from the feasibility labels of the observations: a variational GP classifier (probit link),
    hyperparameters and variational parameters by the ELBO."""

    def __init__(self, space: SearchSpace, X: np.ndarray, failed: np.ndarray, seed: int,
                 descriptors: Mapping[int, np.ndarray] | None = None):
        """X: (n, D) internal points, failed: (n,) bool."""
        require_botorch()
        self.space = space
        self.features = Features(space, descriptors)
        Z = self.inputs(X)
        y = torch.as_tensor(~np.asarray(failed, dtype=bool), dtype=DTYPE)
        with torch.random.fork_rng():
            torch.manual_seed(seed)
            inducing = Z if len(Z) <= MAX_INDUCING else Z[torch.randperm(len(Z))[:MAX_INDUCING]]
            self.model = _VariationalClassifier(inducing.clone()).to(DTYPE)
            self.likelihood = BernoulliLikelihood().to(DTYPE)
            self._fit(Z, y)

    def inputs(self, X: np.ndarray) -> torch.Tensor:
        """(M, D) internal points -> (M, G) classifier inputs, categories one-hot."""
        Z = self.features.of(X).detach()
        if not self.features.cat_dims:
            return Z
        parts, start = [], 0
        categories = [int(self.space.finite_idx[j]) for kind, j, _ in self.features.columns if kind == "category"]
        for column, d in zip(self.features.cat_dims, categories):
            parts += [Z[:, start:column],
                      torch.nn.functional.one_hot(Z[:, column].long(), int(self.space.n_options[d])).to(DTYPE)]
            start = column + 1
        return torch.cat(parts + [Z[:, start:]], dim=1)

    def _fit(self, Z: torch.Tensor, y: torch.Tensor) -> None:
        self.model.train()
        self.likelihood.train()
        mll = VariationalELBO(self.likelihood, self.model, num_data=len(y))
        closure = ForwardBackwardClosure(lambda: -mll(self.model(Z), y), dict(mll.named_parameters()))
        try:
            with warnings.catch_warnings(), gpytorch.settings.cholesky_max_tries(6):
                warnings.simplefilter("ignore")  # GPyTorch's jitter notes: a failure is caught below
                result = fit_gpytorch_mll_torch(mll, closure=closure, step_limit=FIT_STEPS,
                                                optimizer=partial(torch.optim.Adam, lr=FIT_LR), stopping_criterion=None)
        except (RuntimeError, ValueError) as error:  # NotPSDError and other numerical failures of the fit
            raise ClassifierFitError(f"the feasibility classifier could not be fitted: {error}") from None
        if not np.isfinite(result.fval):
            raise ClassifierFitError(f"the ELBO of the feasibility classifier became {-result.fval}")
        self.model.eval()
        self.likelihood.eval()

    @property
    def lengthscales(self) -> np.ndarray:
        """(G,) fitted length scales."""
        return self.model.covar_module.base_kernel.lengthscale.detach().numpy().ravel()

    def probability(self, X: np.ndarray) -> np.ndarray:
        """(M, D) internal points -> (M,) P(feasible)."""
        if not len(X):
            return np.empty(0)
        with torch.no_grad(), gpytorch.settings.fast_pred_var():
            return self.likelihood(self.model(self.inputs(X))).mean.numpy()
