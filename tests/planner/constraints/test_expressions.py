"""The safe expression evaluator: what it computes, and what it refuses when loaded."""

import numpy as np
import pytest

from gryffin_ros.planner import ConfigError, Expression

NAMES = ["F_C", "F_S", "T", "solvent"]


def evaluate(text, **columns):
    arrays = {k: np.asarray(v, dtype=object if isinstance(v[0], str) else float) for k, v in columns.items()}
    return Expression(text, NAMES).evaluate(arrays).tolist()


def test_arithmetic_and_chained_comparison():
    assert evaluate("30 < F_C + F_S < 310", F_C=[10, 100, 200], F_S=[10, 100, 200]) == [False, True, False]


def test_conditional_on_a_category():
    result = evaluate("T < 66 if solvent == 'THF' else T < 100", T=[60, 70, 90, 120],
                      solvent=["THF", "THF", "DMF", "DMF"])
    assert result == [True, False, True, False]


def test_functions_and_boolean_operators():
    assert evaluate("sqrt(F_C) > 3 and not abs(F_S - 5) > 1 or max(F_C, F_S) > 100",
                    F_C=[16, 4, 1], F_S=[5.5, 5, 200]) == [True, False, True]
    assert evaluate("log(exp(F_C)) == F_C and min(F_C, F_S, 3) <= 3", F_C=[2.0], F_S=[7.0]) == [True]


def test_membership_in_a_literal_list():
    assert evaluate("solvent in ('THF', 'MeCN')", solvent=["THF", "DMF", "MeCN"]) == [True, False, True]
    assert evaluate("solvent not in ['THF']", solvent=["THF", "DMF"]) == [False, True]
    assert evaluate("F_C in [-1, 2.5]", F_C=[-1.0, 1.0, 2.5]) == [True, False, True]  # negative numbers are literals


def test_single_point_call():
    assert Expression("F_C < 2 * F_S", NAMES)({"F_C": 10.0, "F_S": 6.0, "T": 1.0, "solvent": "THF"}) is True


@pytest.mark.parametrize("text", [
    "__import__('os').system('true')",
    "F_C.__class__",
    "open('x')",
    "[x for x in F_C]",
    "lambda: 1",
    "F_C[0] > 1",
    "eval('1') == 1",
    "max(F_C, key=F_S) > 1",
    "F_C if F_S",
])
def test_anything_outside_the_whitelist_is_rejected_at_load(text):
    with pytest.raises(ConfigError):
        Expression(text, NAMES)


def test_unknown_name_is_reported_with_the_parameters():
    with pytest.raises(ConfigError, match="unknown name 'F_X'"):
        Expression("F_X < 3", NAMES)


def test_non_boolean_result_fails_on_evaluation():
    with pytest.raises(TypeError, match="true/false"):
        Expression("F_C + 1", NAMES).evaluate({"F_C": np.array([1.0])})
