"""SearchSpace: config parsing, unit conversion at the border, plain Python types out."""

import numpy as np
import pytest

from gryffin_ros.planner import ConfigError, ObservationError, SearchSpace


def space(*specs):
    return SearchSpace.from_config(list(specs))


def test_continuous_round_trip_in_users_units():
    s = space({"name": "T", "type": "continuous", "low": 100, "high": 150})
    X = s.to_internal([{"T": 125.0}, {"T": 100}, {"T": 150}])
    assert np.allclose(X[:, 0], [0.5, 0.0, 1.0])
    assert s.to_params(X) == [{"T": 125.0}, {"T": 100.0}, {"T": 150.0}]


def test_proposals_are_plain_python_types():
    s = space({"name": "T", "type": "continuous", "low": 0, "high": 1},
              {"name": "n", "type": "discrete", "low": 0, "high": 3},
              {"name": "v", "type": "discrete", "options": [0.5, 1.5, 2.5]},
              {"name": "c", "type": "categorical", "options": ["a", "b"]})
    row = s.to_params(s.sample(np.random.default_rng(0), 1))[0]
    assert type(row["T"]) is float and type(row["n"]) is int
    assert type(row["v"]) is float and type(row["c"]) is str


def test_discrete_low_high_is_integers_with_stride_one():
    s = space({"name": "n", "type": "discrete", "low": 2, "high": 5})
    assert s.parameters[0].options == (2, 3, 4, 5)
    assert s.to_internal([{"n": 4}])[0, 0] == 2.0


def test_category_details_alias_with_descriptors_rescaled():
    s = space({"name": "c", "type": "categorical", "category_details": {"a": [0.0, 10.0], "b": [2.0, 20.0],
                                                                        "c": [4.0, 15.0]}})
    assert s.parameters[0].options == ("a", "b", "c")
    assert np.allclose(s.descriptors(0), [[0, 0], [0.5, 1], [1, 0.5]])


def test_category_details_with_none_means_no_descriptors():
    s = space({"name": "c", "type": "categorical", "category_details": {"a": None, "b": None}})
    assert s.descriptors(0) is None


@pytest.mark.parametrize("spec, message", [
    ({"name": "x", "type": "continuous", "low": 1, "high": 0}, "must be below"),
    ({"name": "x", "type": "continuous", "low": 0}, "missing 'high'"),
    ({"name": "x", "type": "continuous", "low": 0, "high": 1, "bounds": [0, 1]}, "unknown key(s) ['bounds']"),
    ({"name": "x", "type": "real", "low": 0, "high": 1}, "'type' must be"),
    ({"name": "x", "type": "discrete", "low": 0.5, "high": 3}, "must be integers"),
    ({"name": "x", "type": "categorical", "options": ["a"]}, "at least two"),
    ({"name": "x", "type": "categorical", "options": ["a", "a"]}, "duplicates"),
    ({"name": "x", "type": "categorical", "options": ["a", "b"], "descriptors": {"a": [1]}}, "missing for options"),
    ({"name": "x y", "type": "continuous", "low": 0, "high": 1}, "identifier"),
    ({"name": "x", "type": "continuous", "low": 0, "high": "1"}, "'high' must be a finite number"),
])
def test_bad_parameter_specs_fail_naming_the_problem(spec, message):
    with pytest.raises(ConfigError, match=None) as info:
        space(spec)
    assert message in str(info.value)


def test_duplicate_parameter_names_are_refused():
    with pytest.raises(ConfigError, match="duplicate parameter name"):
        space({"name": "x", "type": "continuous", "low": 0, "high": 1},
              {"name": "x", "type": "continuous", "low": 0, "high": 1})


@pytest.mark.parametrize("row, message", [
    ({"T": 151.0}, "above its upper bound 150"),
    ({"T": 99.0}, "below its lower bound 100"),
    ({"T": float("nan")}, "not a finite number"),
    ({"T": "120"}, "must be a number"),
    ({"T": True}, "must be a number"),
    ({}, "missing parameter"),
])
def test_out_of_range_and_wrong_type_values_are_rejected(row, message):
    s = space({"name": "T", "type": "continuous", "low": 100, "high": 150})
    with pytest.raises(ObservationError) as info:
        s.to_internal([row])
    assert message in str(info.value)


def test_unknown_category_and_discrete_value_are_rejected():
    s = space({"name": "n", "type": "discrete", "options": [1, 2, 5]},
              {"name": "c", "type": "categorical", "options": ["a", "b"]})
    with pytest.raises(ObservationError, match="not one of its allowed values"):
        s.to_internal([{"n": 3, "c": "a"}])
    with pytest.raises(ObservationError, match="not one of its options"):
        s.to_internal([{"n": 2, "c": "z"}])


def test_periodic_dims_wrap_and_others_clip():
    s = space({"name": "a", "type": "continuous", "low": 0, "high": 360, "periodic": True},
              {"name": "b", "type": "continuous", "low": 0, "high": 1})
    X = s.clip(np.array([[1.25, 1.25], [-0.25, -0.25]]))
    assert np.allclose(X, [[0.25, 1.0], [0.75, 0.0]])


def test_enumerate_and_finite_size():
    s = space({"name": "n", "type": "discrete", "low": 0, "high": 2},
              {"name": "c", "type": "categorical", "options": ["a", "b"]})
    assert s.finite_size == 6
    assert len({tuple(x) for x in s.enumerate()}) == 6
