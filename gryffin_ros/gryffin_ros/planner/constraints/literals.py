"""Names in a config must exist: option literals in constraint expressions, option names in tables.

A constraint such as ``T < (80 if catalyst == 'cui' else 150)`` parses and evaluates, but ``'cui'`` is no option of
``catalyst``, so the comparison is never true and the thermal limit is silently gone. Every literal compared with a
parameter is checked here, when the config is loaded, against what that parameter can actually take.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from ..errors import ConfigError
from ..suggest import suggestion

# A number names a discrete option when it is this close to it, relative (the search space's own matching rule).
MATCH_TOLERANCE = 1e-9

_EQUALITY = (ast.Eq, ast.NotEq, ast.In, ast.NotIn)
_ORDER = (ast.Lt, ast.LtE, ast.Gt, ast.GtE)


def option_list(options: Iterable[Any]) -> str:
    return ", ".join(repr(o) for o in options)


def unknown_option(value: Any, parameter: Any) -> str:
    """"'cui' is not an option of 'catalyst' (options: 'Pd(PPh3)4', 'CuI', 'NiCl2'); did you mean 'CuI'?"."""
    return (f"{value!r} is not an option of '{parameter.name}' (options: {option_list(parameter.options)})"
            f"{suggestion(value, parameter.options)}")


def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def matches_option(value: float, options: Sequence[Any]) -> bool:
    return any(abs(float(o) - value) <= MATCH_TOLERANCE * max(1.0, abs(value)) for o in options)


def literal_values(node: ast.AST) -> list[Any] | None:
    """The values a literal operand can take: a constant, a negated number, ``a if c else b`` of literals, or the
    list/tuple after ``in``; None for anything that is not literal."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float, str)):
        return [node.value]
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = literal_values(node.operand)
        if inner is not None and all(is_number(v) for v in inner):
            return [-v if isinstance(node.op, ast.USub) else v for v in inner]
        return None
    if isinstance(node, ast.IfExp):
        body, orelse = literal_values(node.body), literal_values(node.orelse)
        return None if body is None or orelse is None else body + orelse
    if isinstance(node, (ast.Tuple, ast.List)):
        values = [literal_values(e) for e in node.elts]
        return None if any(v is None for v in values) else [x for v in values for x in v]
    return None


def _parameters_of(node: ast.AST, parameters: Mapping[str, Any]) -> list[Any] | None:
    """The parameters whose value an operand is: a parameter name, or ``a if c else b`` of parameter names; None for
    anything else (arithmetic, calls, literals)."""
    if isinstance(node, ast.Name) and node.id in parameters:
        return [parameters[node.id]]
    if isinstance(node, ast.IfExp):
        body, orelse = _parameters_of(node.body, parameters), _parameters_of(node.orelse, parameters)
        return None if body is None or orelse is None else body + orelse
    return None


def _check_pair(side: ast.AST, op: ast.cmpop, values: list[Any], parameters: Mapping[str, Any]) -> str | None:
    """What is wrong with comparing `side` (an operand) with the literal `values` by `op`, or None."""
    params = _parameters_of(side, parameters)
    booleans = [v for v in values if isinstance(v, bool)]
    if params is not None and booleans:  # True == 1 in Python: `n == True` would silently mean `n == 1`
        return (f"'{params[0].name}' is compared with {booleans[0]!r}; parameters take numbers or option names, "
                "not true/false")
    strings = [v for v in values if isinstance(v, str)]
    if params is None:
        if strings:  # `side` is not literal here: arithmetic, a call, a comparison
            return (f"the string {strings[0]!r} is compared with '{ast.unparse(side)}', which is not a categorical "
                    "parameter, so the comparison can never hold")
        return None
    for p in params:
        if p.kind == "categorical":
            if isinstance(op, _ORDER):
                return f"'{p.name}' is categorical: its options have no order; compare it with ==, !=, in or not in"
            for v in values:
                if not isinstance(v, str):
                    return (f"'{p.name}' is categorical and is compared with the number {v!r}; its options are "
                            f"{option_list(p.options)}")
                if v not in p.options:
                    return unknown_option(v, p)
            continue
        if strings:
            return (f"the string {strings[0]!r} is compared with '{p.name}', a {p.kind} parameter that takes numbers, "
                    "so the comparison can never hold")
        if p.kind == "discrete" and isinstance(op, _EQUALITY):
            for v in values:
                if not matches_option(float(v), p.options):
                    return (f"{v!r} is not an allowed value of '{p.name}' (values: {option_list(p.options)})"
                            f"{suggestion(v, p.options)}")
    return None


def check_literals(tree: ast.AST, text: str, parameters: Mapping[str, Any]) -> None:
    """Refuse (ConfigError) a comparison in a parsed expression whose literal can never match the parameter it is
    compared with: a string that is no option of a categorical parameter, a number that is no value of a discrete
    parameter under ==, !=, in, not in, a string compared with a numeric parameter or with arithmetic, a number
    compared with a categorical parameter, and an order comparison of a categorical parameter."""
    for node in ast.walk(tree):
        if not isinstance(node, ast.Compare):
            continue
        operands = [node.left, *node.comparators]
        for op, left, right in zip(node.ops, operands, operands[1:]):
            problem = None
            right_values, left_values = literal_values(right), literal_values(left)
            if right_values is not None and left_values is None:
                problem = _check_pair(left, op, right_values, parameters)
            elif left_values is not None and right_values is None:
                problem = _check_pair(right, op, left_values, parameters)
            elif right_values is None and left_values is None and isinstance(op, _ORDER):
                for side in (left, right):
                    categorical = [p for p in _parameters_of(side, parameters) or [] if p.kind == "categorical"]
                    if categorical:
                        problem = (f"'{categorical[0].name}' is categorical: its options have no order; compare it "
                                   "with ==, !=, in or not in")
                        break
            if problem:
                raise ConfigError(f"constraint {text!r}: {problem}")
