"""Parameter definitions: continuous, discrete and categorical parameters built from their config entries (Gryffin
format accepted), every key checked."""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import ConfigError
from .molecules import SUBSTRUCTURE, Molecules
from .notices import note_no_effect
from .suggest import suggestion


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
    # with `descriptor_names`: descriptor name -> option -> its value as given (unscaled), for constraints such as
    # `T < boiling_point(solvent) - 5`
    named_descriptors: Mapping[str, Mapping[str, float]] | None = field(default=None, compare=False)
    # options given as SMILES: option -> SMILES, and SMARTS -> option -> match for `has_substructure(p, "SMARTS")`
    smiles: Mapping[str, str] | None = field(default=None, compare=False)
    substructures: Mapping[str, Mapping[str, bool]] | None = field(default=None, compare=False)

    kind = "categorical"


Parameter = ContinuousParameter | DiscreteParameter | CategoricalParameter

# size and process_constrained: Gryffin 1.0 keys, accepted (see parameter_from_spec)
_COMMON_KEYS = {"name", "type", "size", "process_constrained", "units"}
_ALLOWED_KEYS = {
    "continuous": _COMMON_KEYS | {"low", "high", "periodic", "size"},
    "discrete": _COMMON_KEYS | {"low", "high", "options", "size"},
    "categorical": _COMMON_KEYS | {"options", "descriptors", "category_details", "descriptor_names", "size",
                                   "molecular_descriptors"},
}


def _number(spec: Mapping, key: str, where: str) -> float:
    if key not in spec:
        raise ConfigError(f"{where}: missing '{key}'")
    value = spec[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"{where}: '{key}' must be a finite number, got {value!r}")
    return value


def _descriptor_matrix(name: str, options: Sequence[str], table: Mapping) -> np.ndarray | None:
    """The descriptors given per option as an (options, descriptors) matrix, as given; None when there are none."""
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
    return matrix


def _rescaled(matrix: np.ndarray) -> np.ndarray:
    """Each column to [0, 1] (a constant column to 0)."""
    low, high = matrix.min(axis=0), matrix.max(axis=0)
    span = np.where(high > low, high - low, 1.0)
    return (matrix - low) / span


def parameter_from_spec(spec: Mapping[str, Any], position: int, molecules: Molecules | None = None) -> Parameter:
    """Build one parameter from its config dict (Gryffin format accepted), with errors naming the key. A categorical
    parameter whose options are SMILES needs `molecules`, what was computed for them (`molecules.compute`)."""
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
    units = spec.get("units", "")
    if not isinstance(units, str):
        raise ConfigError(f"{where}: 'units' must be a string such as \"degC\" or \"uL/min\", got {units!r}")
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
    if isinstance(options, (Mapping, str)):
        if molecules is None:
            raise ConfigError(f"{where}: options given as SMILES are read by load_config (gryffin_ros.planner), "
                              "which computes their descriptors")
        options = list(molecules.smiles)
    elif "molecular_descriptors" in spec:
        raise ConfigError(f"{where}: 'molecular_descriptors' needs the options as SMILES (option: SMILES)")
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
    given = None
    if table is not None:
        if not isinstance(table, Mapping):
            raise ConfigError(f"{where}: 'descriptors' must map each option to a list of numbers")
        given = _descriptor_matrix(name, options, table)
    named = _named_descriptors(where, spec.get("descriptor_names"), options, table, given)
    if molecules is None:
        return CategoricalParameter(name, tuple(options), None if given is None else _rescaled(given), named)
    clash = sorted(set(named or {}) & set(molecules.properties))
    if clash:
        raise ConfigError(f"{where}: descriptor name(s) {clash} are computed from the SMILES; give your own values "
                          "other names")
    computed = np.array([[molecules.properties[c][o] for c in molecules.columns] for o in options]).reshape(
        len(options), len(molecules.columns))
    matrix = computed if given is None else np.hstack([given, computed])
    if matrix.shape[1]:
        _warn_alike(where, options, matrix)
    return CategoricalParameter(name, tuple(options), _rescaled(matrix) if matrix.shape[1] else None,
                                {**(named or {}), **molecules.properties}, dict(molecules.smiles),
                                molecules.substructures)


def _warn_alike(where: str, options: Sequence[str], matrix: np.ndarray) -> None:
    """Warn about molecules whose descriptors are all equal (isomers, often): the models cannot tell them apart."""
    groups: dict[tuple, list[str]] = {}
    for option, row in zip(options, matrix):
        groups.setdefault(tuple(row), []).append(option)
    alike = [g for g in groups.values() if len(g) > 1]
    if alike:
        logging.getLogger(__name__).warning(
            "%s: options with identical descriptors, which the models cannot tell apart: %s; choose more descriptors "
            "(molecular_descriptors: all, a list) or give your own", where, "; ".join(", ".join(g) for g in alike))


# names a descriptor cannot take: the functions of the constraint expressions
RESERVED_NAMES = {"abs", "sqrt", "exp", "log", "min", "max", SUBSTRUCTURE}


def _named_descriptors(where: str, names: Any, options: Sequence[str], table: Mapping | None,
                       descriptors: np.ndarray | None) -> dict[str, dict[str, float]] | None:
    """`descriptor_names` (one per descriptor column) -> {name: {option: value as given}}."""
    if names is None:
        return None
    if descriptors is None:
        raise ConfigError(f"{where}: 'descriptor_names' needs 'descriptors' (a list of numbers per option)")
    if not isinstance(names, (list, tuple)) or not all(isinstance(n, str) and n.isidentifier() for n in names):
        raise ConfigError(f"{where}: 'descriptor_names' must be a list of names (letters, digits, _), got {names!r}")
    if len(names) != descriptors.shape[1]:
        raise ConfigError(f"{where}: {len(names)} descriptor name(s) for {descriptors.shape[1]} descriptor(s) per "
                          "option")
    if len(set(names)) != len(names):
        raise ConfigError(f"{where}: 'descriptor_names' contains duplicates")
    reserved = sorted(set(names) & RESERVED_NAMES)
    if reserved:
        raise ConfigError(f"{where}: descriptor name(s) {reserved} are functions of the constraint expressions; "
                          "choose other names")
    return {n: {o: float(table[o][k]) for o in options} for k, n in enumerate(names)}
