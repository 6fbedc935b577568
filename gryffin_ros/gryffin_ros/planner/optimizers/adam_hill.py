"""Constrained acquisition optimization with Adam (continuous dims, exact torch autograd gradients) and Hill moves
(discrete and categorical dims). An Adam step that crosses a linear known constraint is projected back onto the
half-spaces (and the box): a projected gradient step, which slides along a boundary the gradient pushes against. A
point whose step still leaves the feasible set (a nonlinear constraint) stops at its last feasible position, as in
the paper. A Hill move is kept only when it improves alpha and stays feasible.
"""

from __future__ import annotations

import numpy as np

from ..acquisition.kernel import Acquisition
from ..constraints import KnownConstraints
from ..reporting import report

BETA1, BETA2, EPSILON = 0.9, 0.999, 1e-8
# Only the best REFINE_FRACTION of the start points (by their acquisition value, at least REFINE_MIN) are refined; the
# others stay candidates at their start values. With wide kernels every start point has a gradient, and refining
# points that start far behind the best rarely changes the proposal.
REFINE_FRACTION, REFINE_MIN = 0.1, 64
PROJECTION_ROUNDS = 8  # cyclic projections onto the violated half-spaces, then the box, at most this many times


class AdamHillOptimizer:
    name = "adam"

    def __init__(self, constraints: KnownConstraints, steps: int = 10, learning_rate: float = 0.01):
        self.constraints = constraints
        self.space = constraints.space
        self.steps = steps
        self.learning_rate = learning_rate

    def optimize(self, acquisition: Acquisition, start: np.ndarray, rng: np.random.Generator
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Refine feasible start points (M, D) -> (refined points (M, D), alpha at them (M,)); all stay feasible.

        Adam runs per point (its own moments, the usual bias correction). A point whose gradient and momentum are
        exactly zero cannot move, so it is not evaluated again until a Hill move changes it.
        """
        keep = len(start) if len(start) <= REFINE_MIN else max(REFINE_MIN, int(REFINE_FRACTION * len(start)))
        if keep < len(start):
            screened = acquisition.evaluate(start)
            best = np.argsort(screened, kind="stable")[:keep]
            X_best, alpha_best = self._refine(acquisition, start[best], rng)
            X, alpha = start.copy(), screened
            X[best], alpha[best] = X_best, alpha_best
            return X, alpha
        return self._refine(acquisition, start, rng)

    def _refine(self, acquisition: Acquisition, start: np.ndarray, rng: np.random.Generator
                ) -> tuple[np.ndarray, np.ndarray]:
        space = self.space
        X = start.copy()
        c, f = space.cont_idx, space.finite_idx
        active = np.ones(len(X), dtype=bool)  # False once an Adam step would have left the feasible set
        still = np.zeros(len(X), dtype=bool)
        m, v = np.zeros((len(X), c.size)), np.zeros((len(X), c.size))
        alpha = None if c.size else acquisition.evaluate(X)
        for step in range(1, self.steps + 1):
            report("optimizing", (step - 1) / self.steps)
            if c.size:
                alpha = self._adam_step(acquisition, X, alpha, active, still, m, v, step)
            if f.size:
                moved = self._hill_step(acquisition, X, alpha, active, rng)
                still[moved] = False
        stale = np.flatnonzero(~still & active) if c.size else np.empty(0, dtype=int)
        if stale.size:
            alpha[stale] = acquisition.evaluate(X[stale])
        return X, alpha

    def _adam_step(self, acquisition: Acquisition, X: np.ndarray, alpha: np.ndarray | None, active: np.ndarray,
                   still: np.ndarray, m: np.ndarray, v: np.ndarray, step: int) -> np.ndarray:
        space = self.space
        idx = np.arange(len(X)) if alpha is None else np.flatnonzero(active & ~still)
        values, grad = acquisition.value_and_grad(X[idx])
        if alpha is None:
            alpha = values
        alpha[idx] = values
        m[idx] = BETA1 * m[idx] + (1 - BETA1) * grad
        v[idx] = BETA2 * v[idx] + (1 - BETA2) * grad ** 2
        delta = self.learning_rate * (m[idx] / (1 - BETA1 ** step)) / (np.sqrt(v[idx] / (1 - BETA2 ** step)) + EPSILON)
        frozen = ~delta.any(axis=1)
        still[idx[frozen]] = True
        idx, delta = idx[~frozen], delta[~frozen]
        if idx.size:
            moved = X[idx].copy()
            moved[:, space.cont_idx] -= delta
            moved = space.clip(moved)
            ok = self.constraints.feasible(moved)
            if not ok.all():
                bad = np.flatnonzero(~ok)
                projected = self._project(moved[bad])
                if projected is not None:
                    good = self.constraints.feasible(projected)
                    moved[bad[good]], ok[bad[good]] = projected[good], True
            X[idx[ok]] = moved[ok]
            active[idx[~ok]] = False
        return alpha

    def _project(self, Y: np.ndarray) -> np.ndarray | None:
        """Y (M, D) moved, in its continuous dims, onto the linear known constraints and the box by cyclic
        projections (each violated half-space in turn, then the box); None where no linear constraint involves a
        continuous dim. The result may still violate a constraint (a nonlinear one, or rounds ran out): the caller
        checks."""
        planes = self.constraints.halfspaces()
        if planes is None:
            return None
        c = self.space.cont_idx
        A, b, _ = planes
        Ac = A[:, c]  # finite dims have no part in a linear constraint (halfspaces()) and do not move here
        rows = np.flatnonzero((Ac ** 2).sum(axis=1) > 0)
        if not rows.size:
            return None
        Y = Y.copy()
        inner = b - 1e-9 * np.maximum(1.0, np.abs(b))  # a hair inside, so that the exact check passes
        for _ in range(PROJECTION_ROUNDS):
            for r in rows:
                excess = Y @ A[r] - inner[r]
                over = excess > 0
                if over.any():
                    Y[np.ix_(over, c)] -= np.outer(excess[over] / (Ac[r] @ Ac[r]), Ac[r])
            Y = self.space.clip(Y)
            if (Y @ A[rows].T <= inner[rows]).all():
                break
        return Y

    def _hill_step(self, acquisition: Acquisition, X: np.ndarray, alpha: np.ndarray, active: np.ndarray,
                   rng: np.random.Generator) -> np.ndarray:
        """One random option per finite dim for every active point, kept where better and feasible; returns the
        indices of the points that moved."""
        space = self.space
        moved = []
        for d in rng.permutation(space.finite_idx):
            idx = np.flatnonzero(active)
            if not idx.size:
                break
            trial = X[idx].copy()
            trial[:, d] = rng.integers(0, space.n_options[d], len(idx))
            trial_alpha = acquisition.evaluate(trial)
            better = trial_alpha < alpha[idx]
            if better.any():
                better[better] = self.constraints.feasible(trial[better])
            X[idx[better]] = trial[better]
            alpha[idx[better]] = trial_alpha[better]
            moved.append(idx[better])
        return np.concatenate(moved) if moved else np.empty(0, dtype=int)

