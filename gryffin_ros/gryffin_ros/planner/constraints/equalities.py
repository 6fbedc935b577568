"""Linear equality constraints and mixtures on continuous parameters, by exact reparametrization.

Rejection sampling can never hit ``x1 + x2 + x3 == 1`` (a set of volume zero), so equalities are not constraints the
planner samples against: they are solved. Gauss-Jordan elimination picks one *dependent* parameter per independent
equation (the latest-declared parameter available, so in a mixture the last component) and writes it as an affine
function of the *free* ones, x_dep = offset - matrix @ x_free (users' units). The planner models and optimizes the free
parameters only; the dependent ones are computed for every proposal and every constraint check, and their bounds
become ordinary (vectorized) inequality constraints on the free ones. Users keep seeing all their parameters.

Config forms (entries of ``constraints``):

- an expression with a single ``==`` whose two sides are linear in continuous parameters: ``"a + b + c == 1"``,
  ``{expression: "2 * T_set - T_probe == 0"}``;
- ``{mixture: {components: [a, b, c], total: 1.0, bounds: {a: [0, 0.7]}}}``: the components sum to ``total``
  (default 1), with optional extra bounds per component (added as inequality constraints).

An ``==`` that involves discrete or categorical parameters stays an ordinary expression constraint (finite dims can be
sampled); a non-linear ``==`` on continuous parameters is refused, naming it.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ConfigError, ObservationError
from ..space import SearchSpace
from ..suggest import suggestion
from .expressions import NotLinear, difference, linear_form, parse
from .named import NamedConstraint
from .specs import ConstraintSpec

# Relative tolerance when checking that a reported observation satisfies the equalities.
OBSERVATION_TOLERANCE = 1e-6


def _equality_sides(text: str) -> tuple[ast.AST, ast.AST] | None:
    try:
        tree = parse(text)
    except SyntaxError:
        return None  # the expression evaluator reports syntax errors with its own message
    body = tree.body
    if isinstance(body, ast.Compare) and len(body.ops) == 1 and isinstance(body.ops[0], ast.Eq):
        return body.left, body.comparators[0]
    return None


@dataclass
class LinearEqualities:
    """x_dep = offset - matrix @ x_free over continuous parameters (users' units)."""

    free: tuple[str, ...]
    dependent: tuple[str, ...]
    offset: np.ndarray  # (m,)
    matrix: np.ndarray  # (m, f)
    rows: list[tuple[dict[str, float], float, str]]  # each equation as given: coefficients, right-hand side, text

    # ---- building --------------------------------------------------------------------------------------------
    @classmethod
    def split(cls, specs: Sequence[ConstraintSpec | Any], space: SearchSpace
              ) -> tuple[LinearEqualities | None, list[ConstraintSpec]]:
        """Config constraint specs -> (the equalities or None, the other specs plus the mixtures' bounds)."""
        continuous = {p.name for p in space.parameters if p.kind == "continuous"}
        periodic = {p.name for p in space.parameters if p.kind == "continuous" and p.periodic}
        every = set(space.names)
        rows: list[tuple[dict[str, float], float, str]] = []
        rest: list[ConstraintSpec] = []
        specs = [ConstraintSpec.of(s, i) for i, s in enumerate(specs)]
        for spec in specs:
            where = spec.where
            if spec.mixture is not None:
                mixture_rows, bounds = cls._mixture(spec, continuous)
                rows += mixture_rows
                rest += [ConstraintSpec(spec.position, expression=bound) for bound in bounds]
                continue
            text = spec.expression if isinstance(spec.expression, str) else None
            sides = _equality_sides(text) if text is not None else None
            if sides is None:
                rest.append(spec)
                continue
            mentioned = {n.id for side in sides for n in ast.walk(side) if isinstance(n, ast.Name)}
            used = mentioned & every
            if used & continuous and mentioned - every:
                unknown = sorted(mentioned - every)
                raise ConfigError(f"{where} '{text}': unknown parameter(s) {unknown}"
                                  f"{suggestion(unknown[0], sorted(every))}")
            if not used & continuous:
                rest.append(spec)  # an equality on finite parameters only: sampled like any expression
                continue
            if used - continuous:
                raise ConfigError(f"{where} '{text}': an equality may mix continuous parameters only; "
                                  f"{sorted(used - continuous)} are discrete or categorical")
            try:
                (a, ca), (b, cb) = (linear_form(side, continuous) for side in sides)
            except NotLinear as exc:
                raise ConfigError(f"{where} '{text}': only linear equalities of continuous parameters can be "
                                  f"satisfied exactly (not linear: {exc})") from None
            coefs = difference(a, b)
            if not coefs:
                raise ConfigError(f"{where} '{text}': no parameter is left after simplification")
            rows.append((coefs, cb - ca, text))
        if not rows:
            return None, specs
        used = {k for coefs, _, _ in rows for k in coefs}
        if used & periodic:
            raise ConfigError(f"equality constraints on periodic parameters {sorted(used & periodic)} are not "
                              "supported")
        return cls._solve(rows, space), rest

    @staticmethod
    def _mixture(spec: ConstraintSpec, continuous: set[str]) -> tuple[list, list[str]]:
        """A mixture's equation (its components sum to the total) and its components' bounds as expressions."""
        where, body = spec.where, spec.mixture
        extra = set(body) - {"components", "total", "bounds"}
        if extra:
            raise ConfigError(f"{where}: unknown mixture key(s) {sorted(extra)}; use components, total, bounds")
        components = body.get("components")
        if not isinstance(components, (list, tuple)) or len(components) < 2 or len(set(components)) != len(components):
            raise ConfigError(f"{where}: mixture 'components' must list at least two distinct parameter names")
        not_continuous = [c for c in components if c not in continuous]
        if not_continuous:
            raise ConfigError(f"{where}: mixture components {not_continuous} are not continuous parameters "
                              f"(continuous: {sorted(continuous)}){suggestion(not_continuous[0], sorted(continuous))}")
        total = body.get("total", 1.0)
        if isinstance(total, bool) or not isinstance(total, (int, float)) or not math.isfinite(total):
            raise ConfigError(f"{where}: mixture 'total' must be a finite number, got {total!r}")
        bounds = body.get("bounds") or {}
        if not isinstance(bounds, Mapping):
            raise ConfigError(f"{where}: mixture 'bounds' must map components to [low, high]")
        extra_constraints = []
        for name, pair in bounds.items():
            if name not in components:
                raise ConfigError(f"{where}: mixture bound for '{name}', which is not a component "
                                  f"(components: {list(components)}){suggestion(name, list(components))}")
            if (not isinstance(pair, (list, tuple)) or len(pair) != 2
                    or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                               for v in pair) or pair[0] > pair[1]):
                raise ConfigError(f"{where}: mixture bound for '{name}' must be [low, high] with low <= high")
            extra_constraints.append(f"{float(pair[0])!r} <= {name} <= {float(pair[1])!r}")
        text = spec.name or f"{' + '.join(components)} == {float(total)!r}"
        return [({c: 1.0 for c in components}, float(total), text)], extra_constraints

    @classmethod
    def _solve(cls, rows: list[tuple[dict[str, float], float, str]], space: SearchSpace) -> LinearEqualities:
        order = [n for n in space.names if any(n in coefs for coefs, _, _ in rows)]
        A = np.array([[coefs.get(n, 0.0) for n in order] for coefs, _, _ in rows])
        b = np.array([rhs for _, rhs, _ in rows])
        scale = max(np.abs(A).max(), 1.0)
        tol = 1e-12 * scale
        pivots: list[int] = []
        r = 0
        for col in reversed(range(len(order))):  # latest-declared parameters become dependent first
            if r == len(A):
                break
            best = r + int(np.argmax(np.abs(A[r:, col])))
            if abs(A[best, col]) <= tol:
                continue
            A[[r, best]], b[[r, best]] = A[[best, r]], b[[best, r]]
            b[r] /= A[r, col]
            A[r] /= A[r, col]
            for other in range(len(A)):
                if other != r and A[other, col] != 0.0:
                    b[other] -= A[other, col] * b[r]
                    A[other] -= A[other, col] * A[r]
            pivots.append(col)
            r += 1
        leftover = np.abs(b[r:])
        if leftover.size and leftover.max() > 1e-9 * max(1.0, np.abs(b).max()):
            raise ConfigError("the equality constraints contradict each other: "
                              + "; ".join(text for _, _, text in rows))
        if len(pivots) == len(order):
            raise ConfigError("the equality constraints fix every parameter they mention ("
                              + ", ".join(order) + "); remove those parameters or the equalities")
        free_cols = [c for c in range(len(order)) if c not in pivots]
        # keep every continuous parameter not solved for as free, in declaration order
        dependent = tuple(order[c] for c in pivots)
        free_all = tuple(n for n in space.names if n not in dependent)
        matrix = np.zeros((len(pivots), len(free_all)))
        for i, _ in enumerate(pivots):
            for c in free_cols:
                matrix[i, free_all.index(order[c])] = A[i, c]
        return cls(free_all, dependent, b[:len(pivots)].copy(), matrix, rows)

    # ---- use -------------------------------------------------------------------------------------------------
    def reduced_space(self, space: SearchSpace) -> SearchSpace:
        return SearchSpace([p for p in space.parameters if p.name not in self.dependent])

    def complete_columns(self, columns: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Free parameter columns -> all columns (the dependent ones computed)."""
        out = dict(columns)
        free = [np.asarray(columns[n], dtype=float) if self.matrix[:, j].any() else None
                for j, n in enumerate(self.free)]
        for i, name in enumerate(self.dependent):
            value = np.full(len(next(iter(columns.values()))) if columns else 1, self.offset[i])
            for j, column in enumerate(free):
                if column is not None and self.matrix[i, j] != 0.0:
                    value = value - self.matrix[i, j] * column
            out[name] = value
        return out

    def complete(self, params: Mapping[str, Any], order: Sequence[str]) -> dict[str, Any]:
        """Free parameters of one point -> all parameters, in `order`."""
        out = dict(params)
        for i, name in enumerate(self.dependent):
            out[name] = float(self.offset[i] - sum(self.matrix[i, j] * float(params[n])
                                                   for j, n in enumerate(self.free) if self.matrix[i, j] != 0.0))
        return {name: out[name] for name in order}

    def check(self, params: Mapping[str, Any]) -> None:
        """Raise ObservationError when reported parameters break an equality (relative tolerance 1e-6)."""
        for coefs, rhs, text in self.rows:
            terms = [coefs[k] * float(params[k]) for k in coefs]
            residual = abs(sum(terms) - rhs)
            if residual > OBSERVATION_TOLERANCE * max(1.0, abs(rhs), *(abs(t) for t in terms)):
                raise ObservationError(f"parameters break the equality '{text}' (residual {residual:.3g})")

    def bound_constraints(self, space: SearchSpace) -> list[NamedConstraint]:
        """Each dependent parameter within its declared bounds, as vectorized constraints on the free ones."""
        out = []
        for i, name in enumerate(self.dependent):
            p = next(q for q in space.parameters if q.name == name)

            def within(columns: Mapping[str, np.ndarray], i: int = i, name: str = name, low: float = p.low,
                       high: float = p.high) -> np.ndarray:
                value = self.complete_columns(columns)[name]
                return (value >= low) & (value <= high)

            def one(params: Mapping[str, Any], fn=within) -> bool:
                return bool(fn({k: np.asarray([v]) for k, v in params.items()})[0])

            constraint = NamedConstraint(f"{name} = {self.formula(i)} within [{p.low:g}, {p.high:g}]", one, within,
                                         derived=True)
            coefs = {n: float(c) for n, c in zip(self.free, self.matrix[i]) if c != 0.0}
            # low <= offset - coefs.x <= high  <=>  coefs.x <= offset - low  and  -coefs.x <= high - offset
            constraint.linear = [(coefs, float(self.offset[i] - p.low)),
                                 ({k: -v for k, v in coefs.items()}, float(p.high - self.offset[i]))]
            out.append(constraint)
        return out

    def formula(self, i: int) -> str:
        terms = [f"{self.offset[i]:g}"] + [f"{'-' if c > 0 else '+'} {abs(c):g}*{n}"
                                           for n, c in zip(self.free, self.matrix[i]) if c != 0.0]
        return " ".join(terms)
