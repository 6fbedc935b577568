"""The ROS-free core of gryffin_ros: search space, known constraints, kernel-density surrogate, acquisition,
constrained acquisition optimizers and the ask/tell Planner (plus Random and Genetic baselines).
"""

from .baselines import Genetic, Random
from .config import PlannerConfig, load_config
from .constraints import FeasibleFraction, KnownConstraints, vectorized
from .errors import (
                     ConfigError,
                     ConstraintError,
                     ExhaustedSpaceError,
                     GryffinRosError,
                     NoFeasiblePointError,
                     ObservationError,
)
from .expressions import Expression
from .planner import BasePlanner, Observation, Planner, Proposal
from .space import SearchSpace

__all__ = [
    "BasePlanner", "ConfigError", "ConstraintError", "ExhaustedSpaceError", "Expression", "FeasibleFraction",
    "Genetic", "GryffinRosError", "KnownConstraints", "NoFeasiblePointError", "Observation", "ObservationError",
    "Planner", "PlannerConfig", "Proposal", "Random", "SearchSpace", "load_config", "vectorized",
]
