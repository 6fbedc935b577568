"""Known constraints: callables, declarative expressions and plugins, combined by AND, plus the feasible fraction V_C.

Constraint plugins are factories ``(options: dict) -> constraint`` registered under the entry-point group
``gryffin_ros.constraints``; the built-ins ``expression``, ``flow_reactor`` and ``lookup`` live here.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

import numpy as np

from .errors import ConfigError, ConstraintError, NoFeasiblePointError
from .expressions import Expression, linear_inequalities
from .literals import matches_option, option_list, suggestion, unknown_option
from .space import Parameter, SearchSpace

PLUGIN_GROUP = "gryffin_ros.constraints"
ENUMERATION_LIMIT = 10**6
# Feasible Monte Carlo hits kept from the V_C estimate (all of them, up to this many) as hit-and-run seeds: a region
# 1000x smaller than the rest still holds a few of 20 000 draws.
KEPT_HITS = 50_000


@dataclass
class NamedConstraint:
    """One known constraint. ``columns_fn`` (vectorized over column arrays) is used when present, else ``fn``."""

    name: str
    fn: Callable[[dict], Any]
    columns_fn: Callable[[Mapping[str, np.ndarray]], np.ndarray] | None = None
    # when the constraint is exactly a set of linear half-spaces sum(coefs * x) <= rhs in users' units
    linear: list[tuple[dict[str, float], float]] | None = None
    # made by the planner itself (an equality-solved parameter kept within its bounds), not written by the user
    derived: bool = False


Parameters = Mapping[str, Parameter]  # every parameter a constraint may name, by name


def expression_constraint(options: Mapping[str, Any], parameters: Parameters) -> NamedConstraint:
    text = options.get("expression") if isinstance(options, Mapping) else None
    expression = Expression(text, parameters, parameters)
    return NamedConstraint(text, expression, expression.evaluate)


def flow_reactor_constraint(options: Mapping[str, Any], parameters: Parameters) -> NamedConstraint:
    """Flow limits of the C60 reactor: min_total < F_C + F_S < max_total, and each flow below ratio x the other."""
    allowed = {"min_total", "max_total", "ratio", "c60_flow", "sultine_flow"}
    unknown = set(options) - allowed
    if unknown:
        raise ConfigError(f"flow_reactor constraint: unknown option(s) {sorted(unknown)}; allowed {sorted(allowed)}")
    fc, fs = options.get("c60_flow", "F_C"), options.get("sultine_flow", "F_S")
    low, high, ratio = options.get("min_total", 30.0), options.get("max_total", 310.0), options.get("ratio", 2.0)
    for key, value in (("min_total", low), ("max_total", high), ("ratio", ratio)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ConfigError(f"flow_reactor constraint: '{key}' must be a finite number, got {value!r}")
    if not low < high:
        raise ConfigError(f"flow_reactor constraint: min_total ({low}) must be below max_total ({high})")
    text = f"{low!r} < {fc} + {fs} < {high!r} and {fc} < {ratio!r} * {fs} and {fs} < {ratio!r} * {fc}"
    expression = Expression(text, parameters, parameters)
    return NamedConstraint(f"flow_reactor({text})", expression, expression.evaluate)


def _lookup_key(value: Any) -> Any:
    """Membership key of one value: numbers compare by value (1 == 1.0), anything else as its text."""
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        return round(float(value), 9)
    text = str(value).strip()
    try:
        return round(float(text), 9)
    except ValueError:
        return text


def lookup_constraint(options: Mapping[str, Any], parameters: Parameters) -> NamedConstraint:
    """Feasible when the parameters form a row of a CSV of feasible combinations (e.g. synthesizable molecules).

    Options: ``file`` (CSV with a header) and ``columns`` (parameter -> CSV column; default: every parameter, by
    its own name).
    """
    unknown = set(options) - {"file", "columns"}
    if unknown:
        raise ConfigError(f"lookup constraint: unknown option(s) {sorted(unknown)}; allowed ['columns', 'file']")
    path = options.get("file")
    if not isinstance(path, str) or not path:
        raise ConfigError("lookup constraint: 'file' must name a CSV file of feasible rows")
    columns = options.get("columns", {name: name for name in parameters})
    if not isinstance(columns, Mapping) or not columns:
        raise ConfigError("lookup constraint: 'columns' must map parameter names to CSV column names")
    unknown = sorted(set(columns) - set(parameters))
    if unknown:
        raise ConfigError(f"lookup constraint: unknown parameter(s) {unknown} in 'columns'"
                          f"{suggestion(unknown[0], list(parameters))}")
    try:
        with open(path, newline="") as handle:
            reader = csv.DictReader(handle)
            missing = set(columns.values()) - set(reader.fieldnames or [])
            if missing:
                raise ConfigError(f"lookup constraint: '{path}' has no column(s) {sorted(missing)}")
            rows = set()
            for row in reader:
                rows.add(tuple(_lookup_cell(row, columns[n], parameters[n], path, reader.line_num)
                               for n in columns))
    except OSError as exc:
        raise ConfigError(f"lookup constraint: cannot read '{path}': {exc.strerror}") from None
    if not rows:
        raise ConfigError(f"lookup constraint: '{path}' holds no rows")
    keys = list(columns)

    def evaluate(cols: Mapping[str, np.ndarray]) -> np.ndarray:
        values = zip(*[[_lookup_key(v) for v in cols[k]] for k in keys])
        return np.fromiter((row in rows for row in values), dtype=bool, count=len(cols[keys[0]]))

    def member(params: Mapping[str, Any]) -> bool:
        return tuple(_lookup_key(params[k]) for k in keys) in rows
    return NamedConstraint(f"lookup({Path(path).name}: {len(rows)} feasible rows)", member, evaluate)


def _lookup_cell(row: Mapping[str, Any], column: str, parameter: Parameter, path: str, line: int) -> Any:
    """One cell of a lookup table as a membership key; a value the parameter cannot take is a ConfigError naming the
    line (a row that can never match would silently make its combination infeasible, or hide a typo)."""
    cell = row.get(column)
    where = f"lookup constraint: '{Path(path).name}' line {line}, column '{column}'"
    if cell is None or not str(cell).strip():
        raise ConfigError(f"{where} is empty")
    key = _lookup_key(cell)
    if parameter.kind == "categorical":
        if key not in {_lookup_key(o) for o in parameter.options}:
            raise ConfigError(f"{where}: {unknown_option(str(cell).strip(), parameter)}")
        return key
    if not isinstance(key, float) or not math.isfinite(key):
        raise ConfigError(f"{where}: {str(cell).strip()!r} is not a number, and '{parameter.name}' is a "
                          f"{parameter.kind} parameter")
    if parameter.kind == "discrete" and not matches_option(key, parameter.options):
        raise ConfigError(f"{where}: {key:g} is not an allowed value of '{parameter.name}' "
                          f"(values: {option_list(parameter.options)}){suggestion(key, parameter.options)}")
    if parameter.kind == "continuous" and not parameter.low <= key <= parameter.high:
        raise ConfigError(f"{where}: {key:g} is outside the range of '{parameter.name}' "
                          f"[{parameter.low:g}, {parameter.high:g}]")
    return key


BUILTIN_PLUGINS = {"expression": expression_constraint, "flow_reactor": flow_reactor_constraint,
                   "lookup": lookup_constraint}


def load_plugin(name: str, options: Mapping[str, Any], parameters: Parameters) -> NamedConstraint:
    """Instantiate a constraint plugin by name: a built-in or a factory registered under the entry-point group."""
    if not isinstance(options, Mapping):
        raise ConfigError(f"constraint plugin '{name}': 'options' must be a mapping")
    if name in BUILTIN_PLUGINS:
        return BUILTIN_PLUGINS[name](options, parameters)
    found = [ep for ep in entry_points(group=PLUGIN_GROUP) if ep.name == name]
    if not found:
        available = sorted(set(BUILTIN_PLUGINS) | {ep.name for ep in entry_points(group=PLUGIN_GROUP)})
        raise ConfigError(f"unknown constraint plugin '{name}'; available: {available}{suggestion(name, available)}")
    try:
        factory = found[0].load()
        constraint = factory(dict(options))
    except ConfigError:
        raise
    except Exception as exc:
        raise ConfigError(f"constraint plugin '{name}' failed to load: {type(exc).__name__}: {exc}") from exc
    if not callable(constraint):
        raise ConfigError(f"constraint plugin '{name}' returned {type(constraint).__name__}, not a callable")
    return NamedConstraint(getattr(constraint, "name", name), constraint, getattr(constraint, "evaluate_columns", None))


def expression_text(spec: Any) -> str | None:
    """The expression of a config entry given as a string or ``{expression: ...}`` (None for plugins and others)."""
    if isinstance(spec, str):
        return spec
    if isinstance(spec, Mapping) and "plugin" not in spec and isinstance(spec.get("expression"), str):
        return spec["expression"]
    return None


def line_limits(A: np.ndarray, b: np.ndarray, X: np.ndarray, V: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For the lines X + t V (rows, internal units), the interval [low, high] of t where A (X + t V) <= b holds
    (-inf / +inf where no half-space bounds it)."""
    slope = V @ A.T
    with np.errstate(divide="ignore", invalid="ignore"):
        limit = (b[None] - X @ A.T) / slope
    return np.where(slope < 0, limit, -np.inf).max(axis=1), np.where(slope > 0, limit, np.inf).min(axis=1)


def constraint_from_spec(spec: Any, position: int, parameters: Parameters) -> NamedConstraint:
    """A config entry: an expression string, ``{expression: ...}`` or ``{plugin: NAME, options: {...}}``."""
    if isinstance(spec, str):
        return expression_constraint({"expression": spec}, parameters)
    if isinstance(spec, Mapping):
        unknown = set(spec) - {"plugin", "options", "expression", "name"}
        if unknown:
            raise ConfigError(f"constraints[{position}]: unknown key(s) {sorted(unknown)}")
        if "expression" in spec and "plugin" in spec:
            raise ConfigError(f"constraints[{position}]: give 'expression' or 'plugin', not both")
        if "expression" not in spec and not isinstance(spec.get("plugin"), str):
            raise ConfigError(f"constraints[{position}]: needs an 'expression' string or a 'plugin' name")
        try:
            if "expression" in spec:
                constraint = expression_constraint(spec, parameters)
            else:
                constraint = load_plugin(spec["plugin"], spec.get("options", {}), parameters)
        except ConfigError as exc:
            if "name" not in spec:
                raise
            raise ConfigError(f"constraints[{position}] ('{spec['name']}'): {exc}") from None
        if "name" in spec:
            constraint.name = str(spec["name"])
        return constraint
    raise ConfigError(f"constraints[{position}] must be an expression string or a mapping, got {type(spec).__name__}")


def vectorized(fn: Callable[[Mapping[str, np.ndarray]], Any]) -> Callable:
    """Mark a known constraint as vectorized: it takes a dict of equal-length column arrays (users' units, categorical
    options as strings) and returns one bool per row, so batches of candidates cost one call instead of one each."""
    fn.vectorized = True
    return fn


def _callable_constraint(fn: Callable, position: int) -> NamedConstraint:
    name = _callable_name(fn, position)
    if not getattr(fn, "vectorized", False):
        return NamedConstraint(name, fn)

    def one(params: Mapping[str, Any]) -> bool:
        result = np.asarray(fn({k: np.asarray([v]) for k, v in params.items()}))
        return bool(result.reshape(-1)[0]) if result.dtype == bool and result.size == 1 else result

    return NamedConstraint(name, one, fn)


def _callable_name(fn: Callable, position: int) -> str:
    name = getattr(fn, "__name__", None) or type(fn).__name__
    return name if name != "<lambda>" else f"known_constraints[{position}]"


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
    def build(cls, space: SearchSpace, specs: Sequence[Any] = (),
              callables: Callable | Sequence[Callable] | None = None,
              parameters: Sequence[Parameter] | None = None) -> KnownConstraints:
        """`parameters`: every parameter a constraint may name (default: the space's; a planner adds those solved
        from equalities)."""
        by_name = {p.name: p for p in (space.parameters if parameters is None else parameters)}
        constraints = [constraint_from_spec(s, i, by_name) for i, s in enumerate(specs)]
        continuous = {p.name for p in space.parameters if p.kind == "continuous"}
        for spec, constraint in zip(specs, constraints):
            text = expression_text(spec)
            if text is not None:
                constraint.linear = linear_inequalities(text, continuous)
        if callables is not None:
            fns = [callables] if callable(callables) else list(callables)
            for i, fn in enumerate(fns):
                if not callable(fn):
                    raise ConfigError(f"known_constraints[{i}] is {type(fn).__name__}, not a callable")
                constraints.append(_callable_constraint(fn, i))
        return cls(space, constraints)

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

    def feasible(self, X: np.ndarray) -> np.ndarray:
        """(M, D) internal points -> (M,) bool. A constraint that raises becomes a ConstraintError naming it."""
        ok = np.ones(len(X), dtype=bool)
        if not self.constraints or not len(X):
            return ok
        columns = self.space.columns(X)
        if self.complete_columns is not None:
            columns = self.complete_columns(columns)
        rows = None
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
        X = self.space.to_internal([params])
        return [c.name for c in self.constraints
                if not KnownConstraints(self.space, [c], self.complete_columns, self.complete_row).feasible(X)[0]]

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


@dataclass(frozen=True)
class FeasibleFraction:
    """V_C, the feasible fraction of the domain, with how it was obtained."""

    value: float
    stderr: float
    method: str  # "given" | "unconstrained" | "enumerated" | "monte_carlo" | "upper_bound"
    samples: int = 0
    # feasible points met while estimating (uniform Monte Carlo hits): seeds for the hit-and-run sampler
    points: np.ndarray | None = field(default=None, compare=False, repr=False)


def estimate_feasible_fraction(constraints: KnownConstraints, rng: np.random.Generator,
                               samples: int = 20000, max_samples: int = 2_000_000) -> FeasibleFraction:
    """Exact enumeration for finite spaces up to 10^6 points, else Monte Carlo with its standard error.

    Monte Carlo keeps doubling the sample when nothing feasible is found, up to ``max_samples``; if still nothing is
    feasible the constraints are taken to exclude (almost) the whole domain and a NoFeasiblePointError is raised.
    """
    space = constraints.space
    if not constraints:
        return FeasibleFraction(1.0, 0.0, "unconstrained")
    size = space.finite_size
    if size is not None and size <= ENUMERATION_LIMIT:
        hits = 0
        points = space.enumerate()
        for start in range(0, len(points), 100_000):
            hits += int(constraints.feasible(points[start:start + 100_000]).sum())
        if hits == 0:
            raise NoFeasiblePointError(f"none of the {size} points of the search space satisfies the known constraints")
        return FeasibleFraction(hits / size, 0.0, "enumerated", size)
    hits, drawn, batch, kept = 0, 0, samples, []
    while True:
        X = space.sample(rng, batch)
        ok = constraints.feasible(X)
        hits += int(ok.sum())
        if sum(len(k) for k in kept) < KEPT_HITS:
            kept.append(X[ok][:KEPT_HITS])
        drawn += batch
        if hits >= 10 or drawn >= max_samples:
            break
        batch = min(drawn, max_samples - drawn)
    if hits == 0:
        raise NoFeasiblePointError(
            f"no point satisfying the known constraints was found in {drawn} uniform samples of the domain "
            f"(feasible fraction below ~{1 / drawn:.1e}); check that the constraints do not contradict each other")
    p = hits / drawn
    return FeasibleFraction(p, math.sqrt(p * (1 - p) / drawn), "monte_carlo", drawn, np.concatenate(kept))


# Points on which each constraint is checked for excluding anything: all of a finite space up to this size (or up to
# ENUMERATION_LIMIT for vectorized constraints), else this many uniform draws.
VACUITY_SAMPLES = 20_000


def vacuous_constraints(constraints: KnownConstraints, rng: np.random.Generator) -> list[str]:
    """A warning for each constraint the user wrote that excludes no point of the domain: exactly over a finite
    space, else over VACUITY_SAMPLES uniform draws. A constraint that constrains nothing is almost always a
    mistake (a bound on the wrong parameter, a limit outside the range, a condition that can never hold)."""
    space = constraints.space
    size = space.finite_size
    points = space.enumerate() if size is not None and size <= ENUMERATION_LIMIT else None
    sample = None
    out = []
    for c in constraints.constraints:
        if c.derived:
            continue
        exact = points is not None and (len(points) <= VACUITY_SAMPLES or c.columns_fn is not None)
        if exact:
            X = points
        else:
            sample = space.sample(rng, VACUITY_SAMPLES) if sample is None else sample
            X = sample
        one = KnownConstraints(space, [c], constraints.complete_columns, constraints.complete_row)
        if one.feasible(X).all():
            where = (f"any of the {len(X)} points of the search space" if exact
                     else f"any of {len(X)} uniform samples of the domain")
            out.append(f"known constraint '{c.name}' excludes no point: it holds at {where}; check it for a "
                       "mistake (a limit outside the parameter's range, a condition that never applies)")
    return out
