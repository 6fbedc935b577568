"""Constraint config entries, parsed once at load into `NamedConstraint`s: expressions, the `lookup` table and plugins.

Plugins are factories registered under the entry-point group ``gryffin_ros.constraints``: ``(options) -> callable``
or, to check the names they use against the search space, ``(options, parameters) -> callable`` (parameters: name ->
definition). The built-ins are ``expression`` and ``lookup``; the flow reactor's plugin is registered by its
emulator package.
"""

from __future__ import annotations

import csv
import inspect
import math
from collections.abc import Mapping
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..space import Parameter
from ..suggest import suggestion
from .expressions import Expression
from .literals import matches_option, option_list, unknown_option
from .named import NamedConstraint, callable_constraint
from .specs import EXPRESSION_OPTIONS, ConstraintSpec

PLUGIN_GROUP = "gryffin_ros.constraints"

Parameters = Mapping[str, Parameter]  # every parameter a constraint may name, by name


def expression_constraint(options: Mapping[str, Any], parameters: Parameters) -> NamedConstraint:
    unknown = sorted(set(options) - EXPRESSION_OPTIONS) if isinstance(options, Mapping) else []
    if unknown:
        raise ConfigError(f"expression constraint: unknown option(s) {unknown}; it takes only 'expression'")
    text = options.get("expression") if isinstance(options, Mapping) else None
    expression = Expression(text, parameters, parameters)
    return NamedConstraint(text, expression, expression.evaluate)


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
            # the option keys of each categorical parameter, once per table (not once per cell)
            option_keys = {n: {_lookup_key(o) for o in parameters[n].options} for n in columns
                           if parameters[n].kind == "categorical"}
            rows = set()
            for row in reader:
                rows.add(tuple(_lookup_cell(row, columns[n], parameters[n], option_keys.get(n), path,
                                            reader.line_num) for n in columns))
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


def _lookup_cell(row: Mapping[str, Any], column: str, parameter: Parameter, option_keys: set | None, path: str,
                 line: int) -> Any:
    """One cell of a lookup table as a membership key (`option_keys`: those of a categorical parameter's options); a
    value the parameter cannot take is a ConfigError naming the line (a row that can never match would silently make
    its combination infeasible, or hide a typo)."""
    cell = row.get(column)
    where = f"lookup constraint: '{Path(path).name}' line {line}, column '{column}'"
    if cell is None or not str(cell).strip():
        raise ConfigError(f"{where} is empty")
    key = _lookup_key(cell)
    if parameter.kind == "categorical":
        if key not in option_keys:
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


BUILTIN_PLUGINS = {"expression": expression_constraint, "lookup": lookup_constraint}


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
        takes_parameters = len(inspect.signature(factory).parameters) >= 2
        constraint = factory(dict(options), parameters) if takes_parameters else factory(dict(options))
    except ConfigError:
        raise
    except Exception as exc:
        raise ConfigError(f"constraint plugin '{name}' failed to load: {type(exc).__name__}: {exc}") from exc
    if isinstance(constraint, NamedConstraint):
        return constraint
    if not callable(constraint):
        raise ConfigError(f"constraint plugin '{name}' returned {type(constraint).__name__}, not a callable")
    if getattr(constraint, "vectorized", False):  # decorated with `vectorized`: takes column arrays
        wrapped = callable_constraint(constraint, 0)
        return NamedConstraint(getattr(constraint, "name", name), wrapped.fn, wrapped.columns_fn)
    return NamedConstraint(getattr(constraint, "name", name), constraint, getattr(constraint, "evaluate_columns", None))


def constraint_from_spec(spec: ConstraintSpec | Any, position: int, parameters: Parameters) -> NamedConstraint:
    """The constraint of a config entry: a `ConstraintSpec`, or an entry as written (an expression string,
    ``{expression: ...}`` or ``{plugin: NAME, options: {...}}``), typed first; `position` is its place in the list."""
    spec = ConstraintSpec.of(spec, position)
    if spec.mixture is not None:
        raise ConfigError(f"{spec.where}: a mixture is an equality of continuous parameters, solved by the planner "
                          "(LinearEqualities), not a constraint to evaluate")
    try:
        if spec.plugin is None:
            constraint = expression_constraint({"expression": spec.expression}, parameters)
        else:
            constraint = load_plugin(spec.plugin, spec.options, parameters)
    except ConfigError as exc:
        if spec.name is None:
            raise
        raise ConfigError(f"{spec.where} ('{spec.name}'): {exc}") from None
    if spec.name is not None:
        constraint.name = spec.name
    return constraint
