"""Campaign configuration: Gryffin-format dicts/JSON/YAML (`general`, `parameters`, `objectives`) plus `constraints`.

Everything is validated when loaded; an unknown key or a wrong type fails with a message naming it.
"""

from __future__ import annotations

import copy
import hashlib
import json
import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from . import molecules
from .constraints.specs import ConstraintSpec, constraint_specs
from .errors import ConfigError
from .molecules import MoleculeCache, Molecules
from .notices import note_no_effect
from .space import SearchSpace

TOP_LEVEL_KEYS = {"name", "general", "parameters", "objectives", "constraints", "database", "model"}
# Gryffin 1.0 keys we accept for compatibility; they change nothing here (ours has no such knob): each is logged once
# per process as having no effect, with the reason below, and documented in docs/gryffin1.md.
_NO_BNN = "there is no Bayesian neural network here; kernels are placed on the observations directly"
_NO_DATABASE = ("Gryffin's database is not written here; the observations are what you pass in, and campaigns run "
                "by the ROS node are kept in the campaign store (gryffin-ros export)")
GRYFFIN_NO_OP_KEYS = {
    "num_cpus": "proposals are computed in this process, vectorized; no worker processes are started",
    "parallel": "proposals are computed in this process, vectorized; no worker processes are started",
    "boosted": "it sets the lower probability bound of Gryffin's BNN kernels; " + _NO_BNN,
    "caching": "it caches Gryffin's BNN kernel evaluations; " + _NO_BNN,
    "backend": "it chooses the framework of Gryffin's BNN; " + _NO_BNN,
    "save_database": _NO_DATABASE,
    "verbosity": "nothing is printed; messages go through Python's logging module",
    "reject_tol": "rejection sampling is bounded by general.max_rejection_draws, and small feasible regions are "
                  "sampled by walks inside them instead of giving up",
}
# Gryffin 1.0's `database` and `model` (BNN) sections: every key is accepted and has no effect here.
GRYFFIN_DATABASE_KEYS = {"format", "path", "log_observations", "log_runtimes"}
GRYFFIN_MODEL_KEYS = {"num_epochs", "learning_rate", "num_draws", "num_layers", "hidden_shape", "weight_loc",
                      "weight_scale", "bias_loc", "bias_scale"}


@dataclass(frozen=True)
class Objective:
    """One objective; with several, `tolerance` (relative to the observed range, or `absolute` in the objective's
    units) says how far from its best a point may be and still count as good on it (Chimera)."""

    name: str
    goal: str = "min"  # "min" | "max"
    tolerance: float = 0.0
    absolute: bool = False


@dataclass(frozen=True)
class GeneralSettings:
    batches: int = 1
    sampling_strategies: int = 2
    num_random_samples: int = 200
    acquisition_optimizer: str = "adam"
    obj_transform: str = "sqrt"
    feasible_fraction: float | None = None
    random_seed: int | None = None
    max_rejection_draws: int = 1_000_000
    softness: float = 1e-3
    # fwt, not Gryffin's fwa: P(feasible) counts as 1 from 0.5 up (acquisition/feasibility.py, FWT_THRESHOLD)
    feas_approach: str = "fwt"
    feas_param: float = 1.0
    feas_model: str = "kde"
    auto_desc_gen: bool = False
    kernel_width: str = "auto"
    concrete_temperature: float = 0.0
    surrogate: str = "portfolio"
    dist_param: float = 0.5


_GENERAL_TYPES: dict[str, tuple[type, ...]] = {
    "batches": (int,), "sampling_strategies": (int,), "num_random_samples": (int,),
    "acquisition_optimizer": (str,), "obj_transform": (str,), "feasible_fraction": (int, float),
    "random_seed": (int,), "max_rejection_draws": (int,), "softness": (int, float),
    "feas_approach": (str,), "feas_param": (int, float), "feas_model": (str,),
    "auto_desc_gen": (bool,),
    "kernel_width": (str,), "concrete_temperature": (int, float), "surrogate": (str,), "dist_param": (int, float),
}
# obj_transform: Gryffin's None (no transform) is our `identity`
_GENERAL_CHOICES = {"acquisition_optimizer": {"adam", "genetic"},
                    "obj_transform": {"sqrt", "cbrt", "square", "identity"},
                    "feas_approach": {"fwt", "fwa", "fia", "fca"}, "feas_model": {"kde", "gp"},
                    "kernel_width": {"auto", "spacing", "gryffin"},
                    "surrogate": {"portfolio", "kde", "gp", "auto"}}


@dataclass
class PlannerConfig:
    name: str
    space: SearchSpace
    objectives: list[Objective]
    general: GeneralSettings
    constraint_specs: list[ConstraintSpec] = field(default_factory=list)
    raw: dict = field(default_factory=dict)
    base_dir: Path | None = None  # relative file names in the config (lookup tables) are taken from here

    @property
    def units(self) -> dict[str, str]:
        """Units of parameters and objectives, by name, as the config gives them (optional; "" where none)."""
        return units_of(self.raw)

    def label(self, name: str) -> str:
        """`name (units)`, or the name alone when it has no units: for axes and column headers."""
        return label(name, self.units)

    @property
    def hash(self) -> str:
        """Stable digest of the configuration, to tell whether a stored campaign belongs to this config. Units are
        labels only: editing them keeps the campaign."""
        entries = {key: [{k: v for k, v in e.items() if k != "units"} if isinstance(e, Mapping) else e
                         for e in self.raw.get(key) or []]
                   for key in ("parameters", "objectives") if isinstance(self.raw.get(key), list)}
        return hashlib.sha256(json.dumps({**self.raw, **entries}, sort_keys=True).encode()).hexdigest()


def units_of(raw: Mapping) -> dict[str, str]:
    """Units of the parameters and objectives of a config dict, by name ("" where none is given)."""
    entries = list(raw.get("parameters") or []) + list(raw.get("objectives") or [])
    return {e["name"]: str(e.get("units") or "") for e in entries if isinstance(e, Mapping) and "name" in e}


def label(name: str, units: Mapping[str, str]) -> str:
    """`name (units)`, or the name alone when it has none: for axes and column headers."""
    return f"{name} ({units[name]})" if units.get(name) else name


def read_config(source: Mapping | str | Path) -> dict:
    """A config dict from a mapping or a YAML/JSON file path (a deep copy: the caller's dict is never changed)."""
    if isinstance(source, Mapping):
        return copy.deepcopy(dict(source))
    if not isinstance(source, (str, Path)):
        raise ConfigError(f"config must be a mapping or a file path, got {type(source).__name__}")
    path = Path(source)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ConfigError(f"cannot read config file '{path}': {exc.strerror}") from None
    try:
        data = json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ConfigError(f"config file '{path}' is not valid {'JSON' if path.suffix == '.json' else 'YAML'}: "
                          f"{exc}") from None
    if not isinstance(data, Mapping):
        raise ConfigError(f"config file '{path}' must hold a mapping at the top level")
    return dict(data)


def _general(spec: Any) -> GeneralSettings:
    if spec is None:
        return GeneralSettings()
    if not isinstance(spec, Mapping):
        raise ConfigError("'general' must be a mapping")
    values: dict[str, Any] = {}
    for key, value in spec.items():
        if key in GRYFFIN_NO_OP_KEYS:
            # a database the user asked for deserves a warning; defaults and knobs of the BNN only a note
            level = logging.WARNING if key == "save_database" and value not in (False, None, "False") else logging.INFO
            note_no_effect(f"general.{key}", GRYFFIN_NO_OP_KEYS[key], level)
            continue
        if key not in _GENERAL_TYPES:
            raise ConfigError(f"unknown key 'general.{key}'; known keys: "
                              f"{sorted(set(_GENERAL_TYPES) | set(GRYFFIN_NO_OP_KEYS))}")
        if value is None and key in ("feasible_fraction", "random_seed"):
            continue
        if value is None and key == "obj_transform":
            value = "identity"
        if isinstance(value, bool) != (_GENERAL_TYPES[key] == (bool,)) or not isinstance(value, _GENERAL_TYPES[key]):
            raise ConfigError(f"'general.{key}' has the wrong type: {value!r}")
        if key in _GENERAL_CHOICES and value not in _GENERAL_CHOICES[key]:
            raise ConfigError(f"'general.{key}' must be one of {sorted(_GENERAL_CHOICES[key])}, got {value!r}")
        values[key] = value
    for key in ("batches", "sampling_strategies", "num_random_samples", "max_rejection_draws"):
        if key in values and values[key] < 1:
            raise ConfigError(f"'general.{key}' must be at least 1, got {values[key]}")
    if "softness" in values and not (values["softness"] >= 0 and math.isfinite(values["softness"])):
        raise ConfigError(f"'general.softness' must be a non-negative number, got {values['softness']}")
    if "concrete_temperature" in values and not (values["concrete_temperature"] >= 0
                                                 and math.isfinite(values["concrete_temperature"])):
        raise ConfigError("'general.concrete_temperature' must be a non-negative number, got "
                          f"{values['concrete_temperature']}")
    if "feas_param" in values and not (values["feas_param"] >= 0 and math.isfinite(values["feas_param"])):
        raise ConfigError(f"'general.feas_param' must be a non-negative number, got {values['feas_param']}")
    if "dist_param" in values and not (values["dist_param"] >= 0 and math.isfinite(values["dist_param"])):
        raise ConfigError(f"'general.dist_param' must be a non-negative number, got {values['dist_param']}")
    fraction = values.get("feasible_fraction")
    if fraction is not None and not (0 < fraction <= 1 and math.isfinite(fraction)):
        raise ConfigError(f"'general.feasible_fraction' must be in (0, 1], got {fraction}")
    return GeneralSettings(**values)


def _gryffin_section(section: str, spec: Any, keys: set[str], why: str) -> None:
    """Gryffin 1.0's `database` or `model` section: every key it knows is accepted (and noted once as having no effect
    here), any other is an error naming it."""
    if spec is None:
        return
    if not isinstance(spec, Mapping):
        raise ConfigError(f"'{section}' must be a mapping")
    unknown = set(spec) - keys
    if unknown:
        raise ConfigError(f"unknown key(s) {sorted(f'{section}.{k}' for k in unknown)}; known keys: {sorted(keys)}")
    for key in spec:
        note_no_effect(f"{section}.{key}", why)


def _objectives(spec: Any, parameter_names: tuple[str, ...]) -> list[Objective]:
    if spec is None:
        spec = [{"name": "obj", "goal": "min"}]
    if not isinstance(spec, (list, tuple)) or not spec:
        raise ConfigError("'objectives' must be a non-empty list")
    out = []
    for i, item in enumerate(spec):
        if not isinstance(item, Mapping):
            raise ConfigError(f"objectives[{i}] must be a mapping")
        unknown = set(item) - {"name", "goal", "tolerance", "absolute", "units"}
        if unknown:
            raise ConfigError(f"objectives[{i}]: unknown key(s) {sorted(unknown)}")
        name, goal = item.get("name"), item.get("goal", "min")
        if not isinstance(name, str) or not name:
            raise ConfigError(f"objectives[{i}]: 'name' must be a non-empty string")
        if name in parameter_names:
            raise ConfigError(f"objective '{name}' has the same name as a parameter")
        if goal not in ("min", "max", "minimize", "maximize"):
            raise ConfigError(f"objective '{name}': 'goal' must be 'min' or 'max', got {goal!r}")
        if not isinstance(item.get("units", ""), str):
            raise ConfigError(f"objective '{name}': 'units' must be a string such as \"$/min\", got "
                              f"{item['units']!r}")
        tolerance, absolute = item.get("tolerance", 0.0), item.get("absolute", False)
        if not isinstance(absolute, bool):
            raise ConfigError(f"objective '{name}': 'absolute' must be true or false, got {absolute!r}")
        if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not math.isfinite(tolerance):
            raise ConfigError(f"objective '{name}': 'tolerance' must be a finite number, got {tolerance!r}")
        if not absolute and not 0.0 <= tolerance <= 1.0:
            raise ConfigError(f"objective '{name}': a relative 'tolerance' must be in [0, 1], got {tolerance} "
                              "(set absolute: true for a tolerance in the objective's units)")
        out.append(Objective(name, goal[:3], float(tolerance), absolute))
    if len({o.name for o in out}) != len(out):
        raise ConfigError("duplicate objective names")
    return out


def _molecules(raw: dict, base_dir: Path | None, cache: MoleculeCache, constraints: list[ConstraintSpec]
               ) -> dict[str, Molecules]:
    """What RDKit computes for the categorical parameters whose options are SMILES, by parameter name. Options read
    from a CSV/SDF file are written into `raw` as option -> SMILES, so the config's hash and the stored config hold
    the molecules themselves."""
    specs = raw["parameters"] if isinstance(raw["parameters"], list) else []
    found: dict[str, tuple[Mapping, dict[str, str]]] = {}
    for i, spec in enumerate(specs):
        if isinstance(spec, Mapping) and spec.get("type") == "categorical" and isinstance(spec.get("name"), str):
            smiles = molecules.smiles_options(spec, base_dir, cache)
            if smiles is not None:
                if isinstance(spec.get("options"), str):
                    specs[i] = spec = {**spec, "options": smiles}
                found[spec["name"]] = (spec, smiles)
    if not found:
        return {}
    texts = [c.expression for c in constraints if isinstance(c.expression, str)]
    patterns = molecules.substructure_patterns(texts, set(found))
    return {name: molecules.compute(name, smiles, molecules.descriptor_columns(spec), patterns.get(name, {}), cache)
            for name, (spec, smiles) in found.items()}


def load_config(source: Mapping | str | Path, base_dir: str | Path | None = None,
                molecule_cache: MoleculeCache | None = None) -> PlannerConfig:
    """Validate a config; relative file names in it are resolved against `base_dir`, by default the folder of the
    config file (or the working directory for a dict). `molecule_cache` holds RDKit's values for SMILES options computed
    earlier (a campaign's store keeps them); what is missing is computed and added to it."""
    raw = read_config(source)
    if base_dir is None and isinstance(source, (str, Path)):
        base_dir = Path(source).resolve().parent
    unknown = set(raw) - TOP_LEVEL_KEYS
    if unknown:
        raise ConfigError(f"unknown top-level config key(s) {sorted(unknown)}; allowed: {sorted(TOP_LEVEL_KEYS)}")
    if "parameters" not in raw:
        raise ConfigError("config has no 'parameters'")
    base = Path(base_dir) if base_dir is not None else None
    constraints = constraint_specs(raw.get("constraints") or [], base)
    space = SearchSpace.from_config(raw["parameters"], _molecules(raw, base, molecule_cache or MoleculeCache(),
                                                                  constraints))
    objectives = _objectives(raw.get("objectives"), space.names)
    general = _general(raw.get("general"))
    _gryffin_section("database", raw.get("database"), GRYFFIN_DATABASE_KEYS, _NO_DATABASE)
    _gryffin_section("model", raw.get("model"), GRYFFIN_MODEL_KEYS, _NO_BNN)
    name = raw.get("name", "campaign")
    if not isinstance(name, str) or not name.strip() or "/" in name or "\\" in name:
        raise ConfigError(f"'name' must be a non-empty string without path separators, got {name!r}")
    return PlannerConfig(name, space, objectives, general, constraints, raw, base)
