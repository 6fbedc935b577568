"""Reading a reported observation: either format, every value checked against the search space, the equalities,
the objectives and the known constraints, once."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from ..config import Objective
from ..constraints import KnownConstraints, LinearEqualities
from ..domain import Observation, objective_value
from ..errors import ObservationError
from ..space import SearchSpace


class ObservationReader:
    """`space` is what the planner models; `full_space` every parameter the user sees (with the ones solved from
    `equalities`)."""

    def __init__(self, space: SearchSpace, full_space: SearchSpace, equalities: LinearEqualities | None,
                 objectives: Sequence[Objective], constraints: KnownConstraints):
        self.space, self.full_space, self.equalities = space, full_space, equalities
        self.objectives, self.constraints = objectives, constraints
        self.parameter_names = full_space.names

    def parse(self, item: Mapping[str, Any] | Observation) -> Observation:
        """Validate one observation: Gryffin style (parameters and objectives as keys, optional experiment_id) or
        structured ``{experiment_id, params, objectives, meta}``. Raises ObservationError naming what is wrong."""
        if isinstance(item, Observation):
            params, objectives, experiment_id, meta = item.params, item.objectives, item.experiment_id, item.meta
        elif isinstance(item, Mapping):
            if "params" in item and "params" not in self.parameter_names:
                unknown = set(item) - {"experiment_id", "params", "objectives", "meta"}
                if unknown:
                    raise ObservationError(f"unknown observation field(s) {sorted(unknown)}")
                params, objectives = item["params"], item.get("objectives")
                experiment_id, meta = item.get("experiment_id"), item.get("meta") or {}
                if objectives is None:
                    objectives = {o.name: None for o in self.objectives}
            else:
                names = {o.name for o in self.objectives}
                unknown = set(item) - set(self.parameter_names) - names - {"experiment_id"}
                if unknown:
                    raise ObservationError(f"unknown key(s) {sorted(unknown)}; parameters are "
                                           f"{list(self.parameter_names)}, objectives {sorted(names)}")
                params = {k: item[k] for k in self.parameter_names if k in item}
                absent = sorted(n for n in names if n not in item)
                if absent:  # not read as a failure: a failed experiment says so, every objective None
                    raise ObservationError(f"missing objective(s) {absent}; report a failed experiment with every "
                                           "objective None")
                objectives = {o.name: item[o.name] for o in self.objectives}
                experiment_id, meta = item.get("experiment_id"), {}
        else:
            raise ObservationError(f"an observation must be a mapping, got {type(item).__name__}")
        if not isinstance(params, Mapping):
            raise ObservationError("'params' must be a mapping")
        if not isinstance(objectives, Mapping):
            raise ObservationError("'objectives' must be a mapping or null")
        if experiment_id is not None and not isinstance(experiment_id, str):
            raise ObservationError(f"experiment_id must be a string, got {experiment_id!r}")
        unknown = set(params) - set(self.parameter_names)
        if unknown:
            raise ObservationError(
                f"unknown parameter(s) {sorted(unknown)}; parameters are {list(self.parameter_names)}")
        X = self.space.to_internal([params])
        clean = self.space.to_params(X)[0]
        for d in self.space.cont_idx:  # keep the caller's exact continuous values, not a unit round trip
            clean[self.space.names[d]] = float(params[self.space.names[d]])
        if self.equalities:
            missing = [n for n in self.equalities.dependent if n not in params]
            if missing:
                raise ObservationError(f"missing parameter(s) {missing}")
            self.full_space.to_internal([params])  # types and bounds of the solved parameters too
            self.equalities.check(params)
            clean = {n: (float(params[n]) if n in self.equalities.dependent else clean[n])
                     for n in self.parameter_names}
        known = {o.name for o in self.objectives}
        extra = set(objectives) - known
        if extra:
            raise ObservationError(f"unknown objective(s) {sorted(extra)}; objectives are {sorted(known)}")
        missing = known - set(objectives)
        if missing:
            raise ObservationError(f"missing objective(s) {sorted(missing)}")
        values = {o.name: objective_value(o.name, objectives[o.name]) for o in self.objectives}
        violated = self.constraints.violated_at(X, clean)
        if violated:
            raise ObservationError(f"parameters {clean} violate the known constraint(s) {violated}")
        X.flags.writeable = False
        return Observation(clean, values, experiment_id, dict(meta), internal=(self.space, X[0]))
