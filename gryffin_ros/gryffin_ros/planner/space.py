"""The search space: the one place where users' units meet the planner's internal ones.

Internally a point is a float vector: continuous parameters in [0, 1], discrete and categorical parameters as the
index of their option (stored as a float so one array holds a mixed point).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .errors import ConfigError, ObservationError
from .molecules import Molecules
from .parameters import (
    CategoricalParameter,
    ContinuousParameter,
    DiscreteParameter,
    Parameter,
    parameter_from_spec,
)

__all__ = ["CategoricalParameter", "ContinuousParameter", "DiscreteParameter", "Parameter", "SearchSpace",
           "parameter_from_spec"]


class SearchSpace:
    """An ordered set of parameters; converts between parameter dicts (users' units) and internal vectors."""

    def __init__(self, parameters: Sequence[Parameter]):
        if not parameters:
            raise ConfigError("'parameters' must list at least one parameter")
        names = [p.name for p in parameters]
        duplicated = sorted({n for n in names if names.count(n) > 1})
        if duplicated:
            raise ConfigError(f"duplicate parameter name(s): {duplicated}")
        self.parameters: tuple[Parameter, ...] = tuple(parameters)
        self.names: tuple[str, ...] = tuple(names)
        self.dim = len(parameters)
        self.continuous = np.array([p.kind == "continuous" for p in parameters])
        self.cont_idx = np.flatnonzero(self.continuous)
        self.finite_idx = np.flatnonzero(~self.continuous)
        self.periodic = np.array([p.kind == "continuous" and p.periodic for p in parameters])
        self.n_options = np.array([1 if p.kind == "continuous" else len(p.options) for p in parameters])
        self._index = {p.name: {o: i for i, o in enumerate(p.options)} for p in parameters if p.kind != "continuous"}

    @classmethod
    def from_config(cls, specs: Any, molecules: Mapping[str, Molecules] | None = None) -> SearchSpace:
        """`molecules`: what was computed for the parameters whose options are SMILES, by name (`load_config`)."""
        if not isinstance(specs, (list, tuple)):
            raise ConfigError("'parameters' must be a list of parameter definitions")
        molecules = molecules or {}
        return cls([parameter_from_spec(spec, i, molecules.get(spec.get("name")) if isinstance(spec, Mapping) else None)
                    for i, spec in enumerate(specs)])

    # ---- sizes ---------------------------------------------------------------------------------------------
    @property
    def is_finite(self) -> bool:
        return not self.continuous.any()

    @property
    def finite_size(self) -> int | None:
        """Number of points of an all-discrete/categorical space (None when a continuous parameter exists)."""
        return int(np.prod(self.n_options, dtype=object)) if self.is_finite else None

    @property
    def log_volume(self) -> float:
        """Log of the domain volume in internal units: 1 per continuous dim, the option count per finite dim."""
        return float(np.log(self.n_options).sum())

    def option_tally(self, X: np.ndarray, d: int) -> np.ndarray:
        """How many of the internal points X (M, D) hold each option of finite dim d: (n_options[d],)."""
        options = np.rint(np.asarray(X, dtype=float).reshape(-1, self.dim)[:, d]).astype(int)
        return np.bincount(options, minlength=int(self.n_options[d]))

    def small_categorical_dims(self, max_options: int) -> list[int]:
        """The dims of the categorical parameters with 2 to `max_options` options: few enough that each option gets
        runs of its own in a campaign."""
        return [int(d) for d in self.finite_idx
                if self.parameters[d].kind == "categorical" and 2 <= len(self.parameters[d].options) <= max_options]

    # ---- conversions ---------------------------------------------------------------------------------------
    def to_internal(self, rows: Sequence[Mapping[str, Any]]) -> np.ndarray:
        """Validate parameter dicts and convert them: (M,) dicts -> (M, D) internal array."""
        out = np.empty((len(rows), self.dim))
        for m, row in enumerate(rows):
            if not isinstance(row, Mapping):
                raise ObservationError(f"a parameter set must be a mapping, got {type(row).__name__}")
            missing = [n for n in self.names if n not in row]
            if missing:
                raise ObservationError(f"missing parameter(s) {missing}")
            for d, p in enumerate(self.parameters):
                out[m, d] = self._value_to_internal(p, row[p.name])
        return out

    def _value_to_internal(self, p: Parameter, value: Any) -> float:
        if p.kind == "categorical":
            if not isinstance(value, str) or value not in self._index[p.name]:
                raise ObservationError(f"parameter '{p.name}' = {value!r} is not one of its options {list(p.options)}")
            return float(self._index[p.name][value])
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ObservationError(f"parameter '{p.name}' must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise ObservationError(f"parameter '{p.name}' = {value} is not a finite number")
        if p.kind == "continuous":
            if value < p.low:
                raise ObservationError(f"parameter '{p.name}' = {value} is below its lower bound {p.low}")
            if value > p.high:
                raise ObservationError(f"parameter '{p.name}' = {value} is above its upper bound {p.high}")
            return (value - p.low) / p.span
        options = np.asarray(p.options, dtype=float)
        i = int(np.argmin(np.abs(options - value)))
        if abs(options[i] - value) > 1e-9 * max(1.0, abs(value)):
            if value < options[0] or value > options[-1]:
                raise ObservationError(
                    f"parameter '{p.name}' = {value} is outside its range [{p.options[0]}, {p.options[-1]}]")
            raise ObservationError(f"parameter '{p.name}' = {value} is not one of its allowed values")
        return float(i)

    def to_params(self, X: np.ndarray) -> list[dict[str, Any]]:
        """(M, D) internal array -> list of parameter dicts in users' units, as plain Python types."""
        columns = self.columns(np.atleast_2d(X))
        values = []
        for p in self.parameters:
            column = columns[p.name]
            if p.kind == "discrete" and p.integer:
                column = column.astype(int)
            values.append(column.tolist())
        return [dict(zip(self.names, row)) for row in zip(*values)]

    def columns(self, X: np.ndarray) -> dict[str, np.ndarray]:
        """Column arrays in users' units (categorical as object arrays of option names), for vectorized constraints."""
        cols: dict[str, np.ndarray] = {}
        for d, p in enumerate(self.parameters):
            x = X[:, d]
            if p.kind == "continuous":
                cols[p.name] = np.clip(p.low + x * p.span, p.low, p.high)
            else:
                cols[p.name] = np.asarray(p.options, dtype=object if p.kind == "categorical" else float)[
                    np.rint(x).astype(int)]
        return cols

    # ---- sampling ------------------------------------------------------------------------------------------
    def sample(self, rng: np.random.Generator, m: int) -> np.ndarray:
        """m points drawn uniformly from the whole domain (internal units)."""
        X = rng.random((m, self.dim))
        if self.finite_idx.size:
            X[:, self.finite_idx] = np.floor(X[:, self.finite_idx] * self.n_options[self.finite_idx])
        return X

    def enumerate(self) -> np.ndarray:
        """Every point of a finite space (internal units), in lexicographic order."""
        if not self.is_finite:
            raise ValueError("only all-discrete/categorical spaces can be enumerated")
        return np.array(list(itertools.product(*[range(k) for k in self.n_options])), dtype=float)

    def clip(self, X: np.ndarray) -> np.ndarray:
        """Bring continuous dims back into [0, 1] (periodic ones wrap) and finite dims onto valid option indices."""
        X = X.copy()
        c = self.cont_idx
        if c.size:
            periodic = self.periodic[c]
            X[:, c[periodic]] = np.mod(X[:, c[periodic]], 1.0)
            X[:, c[~periodic]] = np.clip(X[:, c[~periodic]], 0.0, 1.0)
        f = self.finite_idx
        if f.size:
            X[:, f] = np.clip(np.rint(X[:, f]), 0, self.n_options[f] - 1)
        return X

    def scaled(self, X: np.ndarray) -> np.ndarray:
        """Every dim mapped to [0, 1] (finite dims as index / (options - 1)), for distances between points."""
        S = X.copy()
        f = self.finite_idx
        if f.size:
            S[:, f] = X[:, f] / (self.n_options[f] - 1)
        return S

    def descriptors(self, d: int) -> np.ndarray | None:
        """Descriptor matrix (options, m) used to shape the kernel of finite dim d: discrete dims are ordinal."""
        p = self.parameters[d]
        if p.kind == "discrete":
            values = np.asarray(p.options, dtype=float)
            return ((values - values[0]) / (values[-1] - values[0]))[:, None]
        if p.kind == "categorical":
            return p.descriptors
        return None
