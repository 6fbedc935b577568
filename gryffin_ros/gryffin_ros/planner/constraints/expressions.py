"""A safe evaluator for declarative constraint expressions such as ``"F_C + F_S <= 310"``.

The text is parsed with :mod:`ast` and only a whitelist of node types is compiled into numpy closures that act on
whole columns at once; nothing is ever passed to ``eval``. Anything outside the whitelist fails when loaded.
"""

from __future__ import annotations

import ast
import functools
import operator
from collections.abc import Callable, Iterable, Mapping
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..molecules import CATALOG, SUBSTRUCTURE
from ..suggest import suggestion
from .literals import check_literals, literal_values

Columns = Mapping[str, np.ndarray]
Node = Callable[[Columns], Any]

_BINARY = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
    ast.Pow: operator.pow, ast.Mod: operator.mod, ast.FloorDiv: operator.floordiv,
}
_COMPARE = {
    ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
    ast.Eq: operator.eq, ast.NotEq: operator.ne,
}


def _reduce(fn: Callable) -> Callable:
    return lambda *args: fn.reduce(np.broadcast_arrays(*[np.asarray(a, dtype=float) for a in args]))


_FUNCTIONS: dict[str, tuple[Callable, int, int | None]] = {
    # name: (implementation, min args, max args)
    "abs": (np.abs, 1, 1), "sqrt": (np.sqrt, 1, 1), "exp": (np.exp, 1, 1), "log": (np.log, 1, 1),
    "min": (_reduce(np.minimum), 2, None), "max": (_reduce(np.maximum), 2, None),
}


@functools.lru_cache(maxsize=256)
def parse(text: str) -> ast.Expression:
    """The syntax tree of a constraint expression, parsed once per text and shared by its readers (the evaluator,
    the literal check, the equality and half-space readers), which never change it. Raises SyntaxError."""
    return ast.parse(text.strip(), mode="eval")


class Expression:
    """A compiled constraint expression; ``evaluate(columns)`` returns a boolean array, one entry per row.

    `names` are the parameter names it may use. Given `parameters` (name -> parameter definition), every literal
    compared with a parameter must be something that parameter can take (see `literals.check_literals`).
    """

    def __init__(self, text: str, names: Iterable[str], parameters: Mapping[str, Any] | None = None):
        if not isinstance(text, str) or not text.strip():
            raise ConfigError(f"a constraint expression must be a non-empty string, got {text!r}")
        self.text = text
        self._names = set(names)
        self._parameters = dict(parameters or {})
        try:
            tree = parse(text)
        except SyntaxError as exc:
            raise ConfigError(f"constraint {text!r} is not a valid expression: {exc.msg}") from None
        self.variables: set[str] = set()
        self._root = self._compile(tree.body)
        if parameters is not None:
            check_literals(tree.body, text, parameters)

    def evaluate(self, columns: Columns) -> np.ndarray:
        """Boolean array: True where the row satisfies the expression. Raises TypeError/ValueError on misuse."""
        length = len(next(iter(columns.values())))
        with np.errstate(all="ignore"):
            result = self._root(columns)
        result = np.asarray(result)
        if result.dtype != bool:
            raise TypeError(f"constraint {self.text!r} does not evaluate to true/false (got {result.dtype} values)")
        return np.broadcast_to(result, (length,)).copy()

    def __call__(self, params: Mapping[str, Any]) -> bool:
        columns = {name: np.asarray([params[name]], dtype=object if isinstance(params[name], str) else float)
                   for name in self.variables}
        if not columns:
            columns = {"_": np.zeros(1)}
        return bool(self.evaluate(columns)[0])

    # ---- compilation -----------------------------------------------------------------------------------------
    def _reject(self, node: ast.AST, what: str) -> ConfigError:
        return ConfigError(f"constraint {self.text!r}: {what} is not allowed (at column {node.col_offset + 1})")

    def _compile(self, node: ast.AST) -> Node:
        if isinstance(node, ast.Constant):
            value = node.value
            if isinstance(value, (bool, int, float, str)):
                return lambda cols: value
            raise self._reject(node, f"the literal {value!r}")
        if isinstance(node, ast.Name):
            name = node.id
            if name not in self._names:
                raise ConfigError(f"constraint {self.text!r}: unknown name '{name}'; parameters are "
                                  f"{sorted(self._names)}{suggestion(name, sorted(self._names))}")
            self.variables.add(name)
            return lambda cols: cols[name]
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            fn, left, right = _BINARY[type(node.op)], self._compile(node.left), self._compile(node.right)
            return lambda cols: fn(left(cols), right(cols))
        if isinstance(node, ast.UnaryOp):
            operand = self._compile(node.operand)
            if isinstance(node.op, ast.Not):
                return lambda cols: np.logical_not(operand(cols))
            if isinstance(node.op, ast.USub):
                return lambda cols: -operand(cols)
            if isinstance(node.op, ast.UAdd):
                return operand
        if isinstance(node, ast.BoolOp):
            parts = [self._compile(v) for v in node.values]
            combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
            return lambda cols: combine.reduce([np.asarray(p(cols), dtype=bool) for p in parts]) \
                if len(parts) > 1 else parts[0](cols)
        if isinstance(node, ast.Compare):
            return self._compile_compare(node)
        if isinstance(node, ast.IfExp):
            test, body, orelse = self._compile(node.test), self._compile(node.body), self._compile(node.orelse)
            return lambda cols: np.where(test(cols), body(cols), orelse(cols))
        if isinstance(node, ast.Call):
            return self._compile_call(node)
        raise self._reject(node, f"'{type(node).__name__}'")

    def _compile_compare(self, node: ast.Compare) -> Node:
        operands = [self._compile(node.left)]
        ops = []
        for op, comparator in zip(node.ops, node.comparators):
            if isinstance(op, (ast.In, ast.NotIn)):
                members = literal_values(comparator) if isinstance(comparator, (ast.Tuple, ast.List)) else None
                if members is None or any(isinstance(e, ast.IfExp) for e in comparator.elts):
                    raise self._reject(comparator, "'in' with anything but a literal list")
                negate = isinstance(op, ast.NotIn)
                ops.append(lambda a, b, members=members, negate=negate:
                           np.isin(np.asarray(a, dtype=object), members) != negate)
                operands.append(lambda cols: None)
            elif type(op) in _COMPARE:
                ops.append(_COMPARE[type(op)])
                operands.append(self._compile(comparator))
            else:
                raise self._reject(node, f"the comparison '{type(op).__name__}'")

        def compare(cols: Columns) -> np.ndarray:
            values = [operand(cols) for operand in operands]
            result = True
            for i, op in enumerate(ops):
                result = np.logical_and(result, op(values[i], values[i + 1]))
            return np.asarray(result, dtype=bool)
        return compare

    def _compile_call(self, node: ast.Call) -> Node:
        if node.keywords:
            raise self._reject(node, "keyword arguments")
        if isinstance(node.func, ast.Name) and node.func.id == SUBSTRUCTURE:
            return self._compile_substructure(node)
        if isinstance(node.func, ast.Name) and node.func.id not in _FUNCTIONS:
            return self._compile_descriptor(node)
        if not isinstance(node.func, ast.Name):
            raise self._reject(node, "calling anything but abs, min, max, sqrt, exp, log, has_substructure or a named "
                                     "descriptor")
        fn, low, high = _FUNCTIONS[node.func.id]
        if len(node.args) < low or (high is not None and len(node.args) > high):
            raise self._reject(node, f"{node.func.id}() with {len(node.args)} argument(s)")
        args = [self._compile(a) for a in node.args]
        return lambda cols: fn(*[np.asarray(a(cols), dtype=float) for a in args])


    def _compile_descriptor(self, node: ast.Call) -> Node:
        """`name(parameter)`: the named descriptor of a categorical parameter's option (`descriptor_names`), e.g.
        `boiling_point(solvent)`; looked up per row from the values given in the config."""
        function = node.func.id
        categorical = {n: p for n, p in self._parameters.items() if getattr(p, "kind", None) == "categorical"}
        offered = sorted({d for p in categorical.values() for d in (p.named_descriptors or {})})
        if (len(node.args) != 1 or not isinstance(node.args[0], ast.Name)
                or node.args[0].id not in categorical):
            if function in offered:
                raise self._reject(node, f"{function}() of anything but one categorical parameter's name")
            raise self._reject(node, f"calling '{function}'; functions are abs, min, max, sqrt, exp, log, "
                                     f"{SUBSTRUCTURE} and the named descriptors of categorical parameters {offered}"
                                     f"{suggestion(function, offered)}")
        parameter = categorical[node.args[0].id]
        table = (parameter.named_descriptors or {}).get(function)
        if table is None:
            names = sorted(parameter.named_descriptors or {})
            hint = ("; its descriptors are " + f"{names}{suggestion(function, names)}" if names
                    else " (give it 'descriptors' and 'descriptor_names')")
            if function in CATALOG and parameter.smiles is None:
                hint = f" ({function}() is computed for options given as SMILES: {{option: SMILES}})"
            raise ConfigError(f"constraint {self.text!r}: parameter '{parameter.name}' has no descriptor named "
                              f"'{function}'{hint}")
        self.variables.add(parameter.name)
        return _per_option(parameter.name, table, float, np.nan)

    def _compile_substructure(self, node: ast.Call) -> Node:
        """`has_substructure(parameter, "SMARTS")`: whether the molecule of each row's option contains the pattern;
        matched once per option when the config was loaded."""
        molecular = sorted(n for n, p in self._parameters.items() if getattr(p, "smiles", None) is not None)
        args = node.args
        if len(args) != 2 or not isinstance(args[0], ast.Name) or not (isinstance(args[1], ast.Constant)
                                                                        and isinstance(args[1].value, str)):
            raise self._reject(node, f"{SUBSTRUCTURE}() with anything but a parameter whose options are SMILES "
                                     f"({', '.join(molecular) or 'none here'}) and a SMARTS string")
        name, smarts = args[0].id, args[1].value
        parameter = self._parameters.get(name)
        if parameter is None or getattr(parameter, "smiles", None) is None:
            raise self._reject(node, f"{SUBSTRUCTURE}() of '{name}', whose options are not given as SMILES (those "
                                     f"that are: {molecular or 'none'})")
        table = (parameter.substructures or {}).get(smarts)
        if table is None:  # matched only for the constraints of the config being loaded
            raise ConfigError(f"constraint {self.text!r}: {SUBSTRUCTURE}({name}, {smarts!r}) was not matched when "
                              "the config was loaded; give this constraint in the config's 'constraints'")
        self.variables.add(name)
        return _per_option(name, table, bool, False)


def _per_option(name: str, table: Mapping[str, Any], dtype: type, missing: Any) -> Node:
    """A column of per-option values (`table`: option -> value) looked up from the options in column `name`."""
    options = list(table)
    values = [table[o] for o in options]

    def lookup(cols: Columns) -> np.ndarray:
        column = np.asarray(cols[name], dtype=object)
        out = np.full(column.shape, missing, dtype=dtype)
        for option, value in zip(options, values):
            out[column == option] = value
        return out
    return lookup


# ---- linear forms (equalities solved exactly; linear inequalities as half-spaces) ------------------------
class NotLinear(Exception):
    """An expression that is not a linear form of the given parameters."""


def linear_form(node: ast.AST, names: set[str]) -> tuple[dict[str, float], float]:
    """An expression node -> (coefficients by parameter name, constant); raises NotLinear otherwise."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return {}, float(node.value)
    if isinstance(node, ast.Name):
        if node.id not in names:
            raise NotLinear(node.id)
        return {node.id: 1.0}, 0.0
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        coefs, const = linear_form(node.operand, names)
        sign = -1.0 if isinstance(node.op, ast.USub) else 1.0
        return {k: sign * v for k, v in coefs.items()}, sign * const
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub)):
        (a, ca), (b, cb) = linear_form(node.left, names), linear_form(node.right, names)
        sign = 1.0 if isinstance(node.op, ast.Add) else -1.0
        out = dict(a)
        for k, v in b.items():
            out[k] = out.get(k, 0.0) + sign * v
        return out, ca + sign * cb
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Mult, ast.Div)):
        (a, ca), (b, cb) = linear_form(node.left, names), linear_form(node.right, names)
        if isinstance(node.op, ast.Div):
            if b or cb == 0:
                raise NotLinear("division by a parameter or by zero")
            return {k: v / cb for k, v in a.items()}, ca / cb
        if a and b:
            raise NotLinear("product of parameters")
        scale, (coefs, const) = (ca, (b, cb)) if not a else (cb, (a, ca))
        return {k: scale * v for k, v in coefs.items()}, scale * const
    raise NotLinear(type(node).__name__)


def difference(a: Mapping[str, float], b: Mapping[str, float]) -> dict[str, float]:
    """Coefficients of (a - b), without the parameters that cancel."""
    out = dict(a)
    for k, v in b.items():
        out[k] = out.get(k, 0.0) - v
    return {k: v for k, v in out.items() if v != 0.0}


def linear_inequalities(text: str, continuous: set[str]) -> list[tuple[dict[str, float], float]] | None:
    """An expression that is a conjunction of (possibly chained) <, <=, >, >= comparisons, every side linear in
    continuous parameters -> half-spaces sum(coefs * x) <= rhs (strict ones taken as non-strict: they differ on a set
    of volume zero); None for anything else."""
    try:
        body = parse(text).body
    except SyntaxError:
        return None
    parts = body.values if isinstance(body, ast.BoolOp) and isinstance(body.op, ast.And) else [body]
    out: list[tuple[dict[str, float], float]] = []
    try:
        for part in parts:
            if not isinstance(part, ast.Compare):
                return None
            sides = [linear_form(node, continuous) for node in [part.left, *part.comparators]]
            for op, (a, ca), (b, cb) in zip(part.ops, sides, sides[1:]):
                if isinstance(op, (ast.Lt, ast.LtE)):
                    small, c_small, big, c_big = a, ca, b, cb
                elif isinstance(op, (ast.Gt, ast.GtE)):
                    small, c_small, big, c_big = b, cb, a, ca
                else:
                    return None
                coefs = difference(small, big)
                if not coefs:
                    return None
                out.append((coefs, c_big - c_small))
    except NotLinear:
        return None
    return out
