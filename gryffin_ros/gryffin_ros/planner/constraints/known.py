"""Known constraints: the AND of every constraint of a campaign (config entries, plugins, Python callables),
evaluated on internal points or parameter dicts."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import ConfigError, ConstraintError
from ..space import Parameter, SearchSpace
from .expressions import linear_inequalities
from .named import NamedConstraint, callable_constraint
from .plugins import constraint_from_spec
from .specs import ConstraintSpec


class KnownConstraints:
    """The AND of all known constraints of a campaign, evaluated on internal points or parameter dicts."""

    def __init__(self, space: SearchSpace, constraints: Sequence[NamedConstraint] = (),
                 complete_columns: Callable[[Mapping[str, np.ndarray]], Mapping[str, np.ndarray]] | None = None,
                 complete_row: Callable[[Mapping[str, Any]], dict] | None = None):
        """complete_columns / complete_row add parameters that are not dims of `space` (those solved from equality
        constraints) before any constraint sees a point."""
        self.space = space
        self.constraints = list(constraints)
        self.complete_columns = complete_columns
        self.complete_row = complete_row
        self._halfspaces: tuple[tuple[np.ndarray, np.ndarray, bool] | None] | None = None  # computed once

    @classmethod
    def build(cls, space: SearchSpace, specs: Sequence[ConstraintSpec | Any] = (),
              callables: Callable | Sequence[Callable] | None = None,
              parameters: Sequence[Parameter] | None = None, first: Sequence[NamedConstraint] = (),
              complete_columns: Callable[[Mapping[str, np.ndarray]], Mapping[str, np.ndarray]] | None = None,
              complete_row: Callable[[Mapping[str, Any]], dict] | None = None) -> KnownConstraints:
        """`parameters`: every parameter a constraint may name (default: the space's; a planner adds those solved
        from equalities); `first`: constraints checked before the specs' (the solved parameters' bounds);
        `complete_columns` / `complete_row` as in the constructor."""
        by_name = {p.name: p for p in (space.parameters if parameters is None else parameters)}
        specs = [ConstraintSpec.of(s, i) for i, s in enumerate(specs)]
        constraints = [constraint_from_spec(s, s.position, by_name) for s in specs]
        continuous = {p.name for p in space.parameters if p.kind == "continuous"}
        for spec, constraint in zip(specs, constraints):
            if isinstance(spec.expression, str):
                constraint.linear = linear_inequalities(spec.expression, continuous)
        if callables is not None:
            fns = [callables] if callable(callables) else list(callables)
            for i, fn in enumerate(fns):
                if not callable(fn):
                    raise ConfigError(f"known_constraints[{i}] is {type(fn).__name__}, not a callable")
                constraints.append(callable_constraint(fn, i))
        return cls(space, list(first) + constraints, complete_columns, complete_row)

    def __bool__(self) -> bool:
        return bool(self.constraints)

    def halfspaces(self) -> tuple[np.ndarray, np.ndarray, bool] | None:
        """The linear constraints as A u <= b over the internal coordinates (all dims; finite dims get 0), and whether
        they are all the constraints there are; None when no constraint is linear."""
        if self._halfspaces is None:
            self._halfspaces = (self._linear_rows(),)
        return self._halfspaces[0]

    def _linear_rows(self) -> tuple[np.ndarray, np.ndarray, bool] | None:
        rows, rhs = [], []
        for c in self.constraints:
            for coefs, bound in c.linear or []:
                a = np.zeros(self.space.dim)
                b = bound
                for name, coef in coefs.items():
                    d = self.space.names.index(name)
                    p = self.space.parameters[d]
                    a[d] = coef * p.span  # x = low + span * u
                    b -= coef * p.low
                rows.append(a)
                rhs.append(b)
        if not rows:
            return None
        return np.array(rows), np.array(rhs), all(c.linear is not None for c in self.constraints)

    def feasible(self, X: np.ndarray, rows: list[dict] | None = None) -> np.ndarray:
        """(M, D) internal points -> (M,) bool. A constraint that raises becomes a ConstraintError naming it. `rows`:
        the points as complete parameter dicts in users' units, when the caller has them (else converted here)."""
        ok = np.ones(len(X), dtype=bool)
        if not self.constraints or not len(X):
            return ok
        columns = self.space.columns(X)
        if self.complete_columns is not None:
            columns = self.complete_columns(columns)
        for c in self.constraints:
            idx = np.flatnonzero(ok)
            if not idx.size:
                break
            if c.columns_fn is not None:
                try:
                    result = np.asarray(c.columns_fn({k: v[idx] for k, v in columns.items()}))
                except Exception as exc:
                    raise ConstraintError(f"known constraint '{c.name}' raised {type(exc).__name__}: {exc}") from exc
                if result.dtype != bool or result.shape != idx.shape:
                    raise ConstraintError(f"known constraint '{c.name}' did not return one true/false per point")
                ok[idx] = result
                continue
            if rows is None:
                rows = self.space.to_params(X)
                if self.complete_row is not None:
                    rows = [self.complete_row(r) for r in rows]
            for i in idx:
                ok[i] = self._call(c, rows[i])
        return ok

    def is_feasible(self, params: Mapping[str, Any]) -> bool:
        return bool(self.feasible(self.space.to_internal([params]))[0])

    def violated(self, params: Mapping[str, Any]) -> list[str]:
        """Names of the constraints a (valid) parameter dict violates."""
        return self.violated_at(self.space.to_internal([params]))

    def violated_at(self, X: np.ndarray, params: Mapping[str, Any] | None = None) -> list[str]:
        """Names of the constraints the one point X (internal units, shape (1, D)) violates; `params`, when the caller
        has them, spare constraints that take parameter dicts a conversion back to users' units."""
        rows = None if params is None else [dict(params)]
        if not self.constraints or self.feasible(X, rows)[0]:
            return []
        return [c.name for c in self.constraints
                if not KnownConstraints(self.space, [c], self.complete_columns, self.complete_row).feasible(X, rows)[0]]

    @staticmethod
    def _call(c: NamedConstraint, params: dict) -> bool:
        try:
            result = c.fn(dict(params))
        except Exception as exc:
            raise ConstraintError(
                f"known constraint '{c.name}' raised {type(exc).__name__}: {exc} for parameters {params}") from exc
        if not isinstance(result, (bool, np.bool_)):
            raise ConstraintError(
                f"known constraint '{c.name}' returned {result!r} ({type(result).__name__}) for {params}; "
                "it must return True (feasible) or False (infeasible)")
        return bool(result)
