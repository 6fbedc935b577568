"""Constrained acquisition optimization with Adam (continuous dims, exact torch autograd gradients) and Hill moves
(discrete and categorical dims).

An Adam step that leaves the feasible set is not simply dropped. Under linear known constraints the stepped point is
projected back onto them (with the box: a projected gradient step, which slides along a boundary the gradient pushes
against); otherwise, or where that projection still fails a constraint, the step is cut back to the longest feasible
fraction 1/2, 1/4, ... (at least 2^-BACKTRACKS); failing that, only the dims that can move alone move (the step slides
along the boundary where it allows). Only a point for which none of these works stops its Adam steps; Hill moves
go on for every point, and a point a Hill move changed starts Adam again (its categories changed the feasible set).
A Hill move is kept only when it improves alpha and stays feasible.
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
BACKTRACKS = 2  # a step blocked by a nonlinear constraint is tried at 1/2 and 1/4 of its length
PROJECTION_ROUNDS = 8  # cyclic projections onto the violated half-spaces and the box


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
        adam = np.ones(len(X), dtype=bool)  # False once no feasible part of an Adam step was left (until a Hill move)
        still = np.zeros(len(X), dtype=bool)  # zero gradient and momentum: Adam cannot move it
        fresh = np.zeros(len(X), dtype=bool)  # alpha[i] is the acquisition at X[i]
        m, v = np.zeros((len(X), c.size)), np.zeros((len(X), c.size))
        alpha = np.empty(len(X))
        if not c.size:
            alpha[:], fresh[:] = acquisition.evaluate(X), True
        for step in range(1, self.steps + 1):
            report("optimizing", (step - 1) / self.steps)
            if c.size:
                adam[self._adam_step(acquisition, X, alpha, fresh, adam & ~still, still, m, v, step)] = False
            if f.size:
                # against alpha before this step's Adam move where it moved (a step changes alpha little; that
                # saves an evaluation of every point per step)
                moved = self._hill_step(acquisition, X, alpha, rng)
                still[moved], adam[moved], fresh[moved] = False, True, True
        stale = np.flatnonzero(~fresh)
        if stale.size:
            alpha[stale] = acquisition.evaluate(X[stale])
        return X, alpha

    def _adam_step(self, acquisition: Acquisition, X: np.ndarray, alpha: np.ndarray, fresh: np.ndarray,
                   moving: np.ndarray, still: np.ndarray, m: np.ndarray, v: np.ndarray, step: int) -> np.ndarray:
        """One Adam step of the points `moving` (evaluating alpha and its gradient there first); returns the indices
        of the points whose step had no feasible part (they stay where they are)."""
        space = self.space
        idx = np.flatnonzero(moving)
        if not idx.size:
            return idx
        values, grad = acquisition.value_and_grad(X[idx])
        alpha[idx], fresh[idx] = values, True
        m[idx] = BETA1 * m[idx] + (1 - BETA1) * grad
        v[idx] = BETA2 * v[idx] + (1 - BETA2) * grad ** 2
        delta = self.learning_rate * (m[idx] / (1 - BETA1 ** step)) / (np.sqrt(v[idx] / (1 - BETA2 ** step)) + EPSILON)
        frozen = ~delta.any(axis=1)
        still[idx[frozen]] = True
        idx, delta = idx[~frozen], delta[~frozen]
        if idx.size:
            step_ = np.zeros((idx.size, space.dim))
            step_[:, space.cont_idx] = -delta
            moved, ok = self.feasible_step(X[idx], step_)
            X[idx[ok]] = moved[ok]
            fresh[idx[ok]] = False
            return idx[~ok]
        return idx

    def feasible_step(self, X: np.ndarray, step: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Steps (M, D), zero in finite dims, from feasible points X (M, D): (where each point goes, whether it goes
        anywhere). Y = X + step (in the box) where feasible; else Y projected onto the linear constraints; else the
        longest feasible fraction X + 2^-k step, k <= BACKTRACKS; else the step in the dims that can move alone."""
        space, constraints = self.space, self.constraints
        Y = space.clip(X + step)
        out = Y.copy()
        ok = constraints.feasible(out)
        bad = np.flatnonzero(~ok)
        if bad.size:
            projected = self._project(out[bad])
            if projected is not None:
                good = constraints.feasible(projected)
                out[bad[good]], ok[bad[good]] = projected[good], True
                bad = bad[~good]
        if not bad.size:
            return out, ok
        # the shorter steps of every blocked point, checked in one call
        start, step = X[bad], step[bad]
        shorter = [space.clip(start + step / 2 ** k) for k in range(1, BACKTRACKS + 1)]
        passed = constraints.feasible(np.concatenate(shorter)).reshape(len(shorter), -1)
        left = np.ones(bad.size, dtype=bool)
        for trial, good in zip(shorter, passed):
            take = left & good
            out[bad[take]], left[take] = trial[take], False
        rest = np.flatnonzero(left)
        if rest.size and space.cont_idx.size > 1:
            # at a boundary the gradient pushes against: the step in the dims that can move alone (together where
            # that is feasible, else the longest single one), which slides along the boundary where it allows
            dims = space.cont_idx
            singles = np.repeat(start[rest][None], dims.size, axis=0)
            singles[np.arange(dims.size), :, dims] = Y[bad[rest]][:, dims].T
            alone = np.zeros((rest.size, space.dim), dtype=bool)
            alone[:, dims] = constraints.feasible(singles.reshape(-1, space.dim)).reshape(dims.size, -1).T
            alone &= Y[bad[rest]] != start[rest]  # not where the box stops that dim
            rest = rest[alone.any(axis=1)]
            alone = alone[alone.any(axis=1)]
            together = np.where(alone, Y[bad[rest]], start[rest])
            good = constraints.feasible(together)
            out[bad[rest[good]]], left[rest[good]] = together[good], False
            rest, alone = rest[~good], alone[~good]
            longest = np.argmax(np.where(alone, np.abs(step[rest]), -1.0), axis=1)
            single = start[rest].copy()
            single[np.arange(rest.size), longest] = Y[bad[rest], longest]
            out[bad[rest]], left[rest] = single, False
        ok[bad[~left]] = True
        return out, ok

    def _project(self, Y: np.ndarray) -> np.ndarray | None:
        """Y (M, D) moved, in its continuous dims, onto the linear known constraints and the box by cyclic
        projections (each violated half-space in turn, then the box); None where there is no linear constraint on a
        continuous dim. The result may still violate a constraint: the caller checks."""
        planes = self.constraints.halfspaces()
        c = self.space.cont_idx
        if planes is None:
            return None
        A, b, _ = planes
        Ac = A[:, c]  # finite dims have no part in a linear constraint (halfspaces()), and they do not move here
        rows = np.flatnonzero((Ac ** 2).sum(axis=1) > 0)
        if not rows.size:
            return None
        Y = Y.copy()
        # a hair inside each half-space, so that points on it pass the exact check
        inner = b - 1e-9 * np.maximum(1.0, np.abs(b))
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

    def _hill_step(self, acquisition: Acquisition, X: np.ndarray, alpha: np.ndarray, rng: np.random.Generator
                   ) -> np.ndarray:
        """One random option per finite dim for every point, kept where better and feasible; returns the indices of
        the points that moved."""
        space = self.space
        moved = []
        idx = np.arange(len(X))
        for d in rng.permutation(space.finite_idx):
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

