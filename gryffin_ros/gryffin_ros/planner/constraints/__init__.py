"""Known constraints, parsed once when the config loads into typed objects: expressions (checked against the search
space: every name and option they use must exist), equalities and mixtures (solved exactly), the lookup table and
plugins, Python callables; their AND (`KnownConstraints`), the geometry of the linear ones, the feasible fraction V_C
and sampling inside the feasible region."""

from .equalities import LinearEqualities
from .expressions import Expression
from .geometry import line_limits
from .known import KnownConstraints
from .named import NamedConstraint, vectorized
from .plugins import PLUGIN_GROUP, constraint_from_spec, load_plugin
from .region import ENUMERATION_LIMIT, FeasibleFraction, estimate_feasible_fraction, vacuous_constraints
from .specs import ConstraintSpec, constraint_specs

__all__ = [
    "ENUMERATION_LIMIT", "PLUGIN_GROUP", "ConstraintSpec", "Expression", "FeasibleFraction", "KnownConstraints",
    "LinearEqualities", "NamedConstraint", "constraint_from_spec", "constraint_specs", "estimate_feasible_fraction",
    "line_limits", "load_plugin", "vacuous_constraints", "vectorized",
]
