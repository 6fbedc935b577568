"""Known constraints, parsed once when the config loads into typed objects: expressions (checked against the search
space: every name and option they use must exist), equalities and mixtures (solved exactly), the lookup table and
plugins, Python callables; their AND (`KnownConstraints`), the geometry of the linear ones, the feasible fraction V_C
and sampling inside the feasible region."""

from .equalities import LinearEqualities
from .expressions import Expression
from .geometry import line_limits
from .known import KnownConstraints
from .named import NamedConstraint, vectorized
from .plugins import PLUGIN_GROUP, constraint_from_spec, expression_text, load_plugin
from .region import ENUMERATION_LIMIT, FeasibleFraction, estimate_feasible_fraction, vacuous_constraints

__all__ = [
    "ENUMERATION_LIMIT", "PLUGIN_GROUP", "Expression", "FeasibleFraction", "KnownConstraints", "LinearEqualities",
    "NamedConstraint", "constraint_from_spec", "estimate_feasible_fraction", "expression_text", "line_limits",
    "load_plugin", "vacuous_constraints", "vectorized",
]
