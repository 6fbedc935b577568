"""The search space: parameter definitions and the one place where users' units meet the planner's internal ones.

Internally a point is a float vector: continuous parameters in [0, 1], discrete and categorical parameters as the
index of their option (stored as a float so one array holds a mixed point).
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import ConfigError, ObservationError
from .literals import suggestion
from .notices import note_no_effect


@dataclass(frozen=True)
class ContinuousParameter:
    name: str
    low: float
    high: float
    periodic: bool = False

    kind = "continuous"

    @property
    def span(self) -> float:
        return self.high - self.low


@dataclass(frozen=True)
class DiscreteParameter:
    """Ordered numeric options (integers low..high with stride 1, or an explicit ascending list)."""

    name: str
    options: tuple
    integer: bool

    kind = "discrete"


@dataclass(frozen=True)
class CategoricalParameter:
    """Unordered named options, optionally with one descriptor vector per option (rescaled to [0, 1] per column)."""

    name: str
    options: tuple
    descriptors: np.ndarray | None = field(default=None, compare=False)

    kind = "categorical"


Parameter = ContinuousParameter | DiscreteParameter | CategoricalParameter

# size and process_constrained: Gryffin 1.0 keys, accepted (see parameter_from_spec)
_COMMON_KEYS = {"name", "type", "size", "process_constrained"}
_ALLOWED_KEYS = {
    "continuous": _COMMON_KEYS | {"low", "high", "periodic", "size"},
    "discrete": _COMMON_KEYS | {"low", "high", "options", "size"},
    "categorical": _COMMON_KEYS | {"options", "descriptors", "category_details", "size"},
}


def _number(spec: Mapping, key: str, where: str) -> float:
    if key not in spec:
        raise ConfigError(f"{where}: missing '{key}'")
    value = spec[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"{where}: '{key}' must be a finite number, got {value!r}")
    return value


def _rescale_descriptors(name: str, options: Sequence[str], table: Mapping) -> np.ndarray | None:
    unknown = [key for key in table if key not in options]
    if unknown:
        raise ConfigError(f"parameter '{name}': descriptors given for {unknown[0]!r}, which is not one of its options "
                          f"({', '.join(repr(o) for o in options)}){suggestion(unknown[0], list(options))}")
    rows = [table.get(option) for option in options]
    if all(row is None or (isinstance(row, (list, tuple)) and not row) for row in rows):
        return None  # no descriptors (Gryffin 1.0 writes them as empty lists)
    if any(row is None for row in rows):
        missing = [o for o, row in zip(options, rows) if row is None]
        raise ConfigError(f"parameter '{name}': descriptors missing for options {missing}")
    try:
        matrix = np.asarray(rows, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"parameter '{name}': descriptors must be lists of numbers of equal length") from exc
    if matrix.ndim != 2 or matrix.shape[1] == 0:
        raise ConfigError(f"parameter '{name}': descriptors must be non-empty lists of numbers of equal length")
    if not np.all(np.isfinite(matrix)):
        raise ConfigError(f"parameter '{name}': descriptors must be finite numbers")
    low, high = matrix.min(axis=0), matrix.max(axis=0)
    span = np.where(high > low, high - low, 1.0)
    return (matrix - low) / span


def parameter_from_spec(spec: Mapping[str, Any], position: int) -> Parameter:
    """Build one parameter from its config dict (Gryffin format accepted), with errors naming the key."""
    if not isinstance(spec, Mapping):
        raise ConfigError(f"parameters[{position}] must be a mapping, got {type(spec).__name__}")
    name = spec.get("name")
    if not isinstance(name, str) or not name.isidentifier():
        raise ConfigError(f"parameters[{position}]: 'name' must be an identifier string, got {name!r}")
    where = f"parameter '{name}'"
    kind = spec.get("type")
    if kind not in _ALLOWED_KEYS:
        raise ConfigError(f"{where}: 'type' must be continuous, discrete or categorical, got {kind!r}")
    unknown = set(spec) - _ALLOWED_KEYS[kind]
    if unknown:
        raise ConfigError(f"{where}: unknown key(s) {sorted(unknown)} for a {kind} parameter")
    size = spec.get("size", 1)
    if isinstance(size, bool) or not isinstance(size, int) or size < 1:
        raise ConfigError(f"{where}: 'size' must be a positive integer, got {size!r}")
    if size != 1:  # Phoenics' vector parameters; Gryffin 1.0 reads one value per parameter name and ignores `size`
        note_no_effect(f"parameters.{name}.size", f"'{name}' is one dimension, as in Gryffin 1.0, which ignores "
                       "'size'; list each dimension as its own parameter", logging.WARNING)
    if spec.get("process_constrained", False) not in (False, 0, None):
        note_no_effect(f"parameters.{name}.process_constrained", "Gryffin's process constraint is not implemented: the "
                       f"proposals of one recommendation do not share the value of '{name}'", logging.WARNING)

    if kind == "continuous":
        low, high = _number(spec, "low", where), _number(spec, "high", where)
        if not low < high:
            raise ConfigError(f"{where}: 'low' ({low}) must be below 'high' ({high})")
        periodic = spec.get("periodic", False)
        if not isinstance(periodic, bool):
            raise ConfigError(f"{where}: 'periodic' must be true or false, got {periodic!r}")
        return ContinuousParameter(name, float(low), float(high), periodic)

    if kind == "discrete":
        if "options" in spec:
            if "low" in spec or "high" in spec:
                raise ConfigError(f"{where}: give either 'options' or 'low'/'high', not both")
            options = spec["options"]
            if not isinstance(options, (list, tuple)) or len(options) < 2:
                raise ConfigError(f"{where}: 'options' must be a list of at least two numbers")
            for value in options:
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                    raise ConfigError(f"{where}: option {value!r} is not a finite number")
            if len(set(options)) != len(options):
                raise ConfigError(f"{where}: 'options' contains duplicates")
            integer = all(isinstance(v, int) for v in options)
            return DiscreteParameter(name, tuple(sorted(options)), integer)
        low, high = _number(spec, "low", where), _number(spec, "high", where)
        if int(low) != low or int(high) != high:
            raise ConfigError(f"{where}: 'low' and 'high' of a discrete parameter must be integers")
        if not low < high:
            raise ConfigError(f"{where}: 'low' ({low}) must be below 'high' ({high})")
        return DiscreteParameter(name, tuple(range(int(low), int(high) + 1)), True)

    options = spec.get("options")
    details = spec.get("category_details")
    for table in (details, spec.get("descriptors")):
        if options is None and isinstance(table, Mapping):
            options = list(table)
    if isinstance(details, str):
        raise ConfigError(f"{where}: 'category_details' as a file path is not supported; give a mapping option -> list")
    if not isinstance(options, (list, tuple)) or len(options) < 2:
        raise ConfigError(f"{where}: 'options' must be a list of at least two option names")
    if not all(isinstance(o, str) and o for o in options):
        raise ConfigError(f"{where}: every option must be a non-empty string")
    if len(set(options)) != len(options):
        raise ConfigError(f"{where}: 'options' contains duplicates")
    if "descriptors" in spec and details is not None:
        raise ConfigError(f"{where}: give either 'descriptors' or 'category_details', not both")
    table = spec.get("descriptors", details)
    descriptors = None
    if table is not None:
        if not isinstance(table, Mapping):
            raise ConfigError(f"{where}: 'descriptors' must map each option to a list of numbers")
        descriptors = _rescale_descriptors(name, options, table)
    return CategoricalParameter(name, tuple(options), descriptors)


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
    def from_config(cls, specs: Any) -> SearchSpace:
        if not isinstance(specs, (list, tuple)):
            raise ConfigError("'parameters' must be a list of parameter definitions")
        return cls([parameter_from_spec(spec, i) for i, spec in enumerate(specs)])

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
