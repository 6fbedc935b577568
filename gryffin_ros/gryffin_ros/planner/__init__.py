"""The ROS-free core of gryffin_ros: search space, known constraints, surrogates, acquisitions, constrained
acquisition optimizers and the ask/tell Planner (plus Random and Genetic baselines).

Layout: `domain` (Observation, Proposal), `config`, `space` (the one place units are converted), `constraints/`
(parsed once at load: expressions, equalities, lookup, plugins, geometry, V_C, sampling inside the feasible region),
`surrogates/` (kernel density, GP, failure model, descriptors, the per-ask choice), `acquisition/`, `optimizers/`
(Adam + Hill, genetic), `strategies/` (BasePlanner, Planner, baselines, selection), `chimera` (several objectives).
"""

from .config import PlannerConfig, load_config
from .constraints import Expression, FeasibleFraction, KnownConstraints, vectorized
from .domain import Observation, Proposal
from .errors import (
                     ConfigError,
                     ConstraintError,
                     ExhaustedSpaceError,
                     GryffinRosError,
                     NoFeasiblePointError,
                     ObservationError,
)
from .space import SearchSpace
from .strategies import BasePlanner, Genetic, Planner, Random

__all__ = [
    "BasePlanner", "ConfigError", "ConstraintError", "ExhaustedSpaceError", "Expression", "FeasibleFraction",
    "Genetic", "GryffinRosError", "KnownConstraints", "NoFeasiblePointError", "Observation", "ObservationError",
    "Planner", "PlannerConfig", "Proposal", "Random", "SearchSpace", "load_config", "vectorized",
]
