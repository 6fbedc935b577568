"""The one exception hierarchy of the planner: every error a caller can act on derives from GryffinRosError."""


class GryffinRosError(Exception):
    """Base class of every error raised by gryffin_ros on purpose."""


class ConfigError(GryffinRosError, ValueError):
    """The campaign configuration is malformed, contradicts itself or names something unknown."""


class ObservationError(GryffinRosError, ValueError):
    """An observation (or a parameter dict) does not fit the search space or the objectives."""


class ConstraintError(GryffinRosError):
    """A known constraint could not be evaluated (it raised, or returned something that is not a bool)."""


class NoFeasiblePointError(GryffinRosError):
    """No point satisfying the known constraints could be found within the sampling budget."""


class ExhaustedSpaceError(GryffinRosError):
    """Every feasible point of a finite search space has already been observed or proposed."""
