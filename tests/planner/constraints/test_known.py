"""Known constraints: callables, expressions, plugins; errors that name the constraint; the feasible fraction V_C."""

from pathlib import Path

import numpy as np
import pytest

from gryffin_ros.planner import (
    ConfigError,
    ConstraintError,
    KnownConstraints,
    NoFeasiblePointError,
    ObservationError,
    Planner,
    SearchSpace,
)
from gryffin_ros.planner.constraints import estimate_feasible_fraction

SQUARE = SearchSpace.from_config([{"name": "x0", "type": "continuous", "low": 0, "high": 1},
                                  {"name": "x1", "type": "continuous", "low": 0, "high": 1}])
GRID = SearchSpace.from_config([{"name": "x0", "type": "discrete", "low": 0, "high": 20},
                                {"name": "x1", "type": "discrete", "low": 0, "high": 20}])


def test_constraints_combine_by_and():
    c = KnownConstraints.build(SQUARE, ["x0 < 0.5"], [lambda p: p["x1"] < 0.5])
    X = np.array([[0.2, 0.2], [0.7, 0.2], [0.2, 0.7], [0.7, 0.7]])
    assert c.feasible(X).tolist() == [True, False, False, False]


def test_a_raising_callable_is_an_error_naming_it():
    def pump_limit(params):
        raise RuntimeError("pump offline")
    c = KnownConstraints.build(SQUARE, callables=pump_limit)
    with pytest.raises(ConstraintError, match="'pump_limit' raised RuntimeError: pump offline"):
        c.feasible(np.array([[0.1, 0.1]]))


def test_a_callable_returning_a_non_bool_is_an_error():
    c = KnownConstraints.build(SQUARE, callables=lambda p: "yes")
    with pytest.raises(ConstraintError, match="must return True"):
        c.feasible(np.array([[0.1, 0.1]]))


def test_an_expression_misused_at_runtime_names_it():
    space = SearchSpace.from_config([{"name": "c", "type": "categorical", "options": ["a", "b"]}])
    c = KnownConstraints.build(space, ["c + 1 > 2"])
    with pytest.raises(ConstraintError, match="'c \\+ 1 > 2' raised"):
        c.feasible(np.array([[0.0]]))


def test_violated_lists_the_names():
    c = KnownConstraints.build(SQUARE, ["x0 < 0.5", {"expression": "x1 < 0.5", "name": "upper"}])
    assert c.violated({"x0": 0.7, "x1": 0.7}) == ["x0 < 0.5", "upper"]
    assert c.violated({"x0": 0.1, "x1": 0.1}) == []


@pytest.mark.parametrize("spec, message", [
    ({"plugin": "no_such_plugin"}, "unknown constraint plugin 'no_such_plugin'"),
    ({"expression": "x0 < 1", "plugin": "flow_reactor"}, "not both"),
    ({"when": "x0 < 1"}, "unknown key(s) ['when']"),
    (42, "must be an expression string or a mapping"),
])
def test_bad_constraint_specs_fail_at_load(spec, message):
    with pytest.raises(ConfigError) as info:
        KnownConstraints.build(SQUARE, [spec])
    assert message in str(info.value)


def test_unconstrained_fraction_is_one():
    assert estimate_feasible_fraction(KnownConstraints(SQUARE), np.random.default_rng(0)).value == 1.0


def test_monte_carlo_fraction_with_standard_error():
    c = KnownConstraints.build(SQUARE, ["x0 + x1 <= 1"])
    f = estimate_feasible_fraction(c, np.random.default_rng(0), samples=40000)
    assert f.method == "monte_carlo"
    assert abs(f.value - 0.5) < 4 * f.stderr
    assert 0.001 < f.stderr < 0.005


def test_finite_space_fraction_is_exact():
    c = KnownConstraints.build(GRID, callables=lambda p: not 5 < p["x0"] ** 2 + p["x1"] ** 2 < 25)
    f = estimate_feasible_fraction(c, np.random.default_rng(0))
    expected = sum(not 5 < i * i + j * j < 25 for i in range(21) for j in range(21)) / 441
    assert f.method == "enumerated" and f.value == expected and f.stderr == 0.0


def test_contradictory_constraints_give_a_clear_error_not_a_hang():
    c = KnownConstraints.build(SQUARE, ["x0 < 0.2", "x0 > 0.8"])
    with pytest.raises(NoFeasiblePointError, match="no point satisfying the known constraints"):
        estimate_feasible_fraction(c, np.random.default_rng(0), max_samples=100_000)


def test_a_plugin_may_return_a_vectorized_constraint(monkeypatch, tmp_path):
    """A factory's callable decorated with `vectorized` gets column arrays, per point as for a batch."""
    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[2] / "plugin_package"))
    c = KnownConstraints.build(SQUARE, [{"plugin": "test_gate", "options": {"hold": str(tmp_path / "hold")}}])
    assert c.constraints[0].columns_fn is not None
    assert c.feasible(np.random.default_rng(0).random((50, 2))).tolist() == [True] * 50
    assert c.is_feasible({"x0": 0.3, "x1": 0.9})


def test_lookup_plugin_accepts_exactly_the_listed_rows(tmp_path):
    space = SearchSpace.from_config([{"name": "r1", "type": "categorical", "options": ["A", "B", "C"]},
                                     {"name": "n", "type": "discrete", "low": 1, "high": 3}])
    table = tmp_path / "feasible.csv"
    table.write_text("group,count,note\nA,1,x\nB,3.0,y\nC,2,z\n")
    c = KnownConstraints.build(space, [{"plugin": "lookup", "options": {"file": str(table),
                                                                        "columns": {"r1": "group", "n": "count"}}}])
    feasible = {(p["r1"], p["n"]) for p in space.to_params(space.enumerate()) if c.is_feasible(p)}
    assert feasible == {("A", 1), ("B", 3), ("C", 2)}
    assert c.feasible(space.enumerate()).sum() == 3


@pytest.mark.parametrize("options, message", [
    ({}, "'file' must name a CSV file"),
    ({"file": "/nonexistent.csv"}, "cannot read"),
    ({"file": "TABLE", "columns": {"r9": "group"}}, "unknown parameter(s) ['r9']"),
    ({"file": "TABLE", "columns": {"r1": "missing"}}, "has no column(s) ['missing']"),
    ({"file": "TABLE", "sheet": 1}, "unknown option(s) ['sheet']"),
])
def test_lookup_plugin_config_errors(tmp_path, options, message):
    space = SearchSpace.from_config([{"name": "r1", "type": "categorical", "options": ["A", "B"]}])
    table = tmp_path / "t.csv"
    table.write_text("group\nA\n")
    options = {k: (str(table) if v == "TABLE" else v) for k, v in options.items()}
    with pytest.raises(ConfigError) as info:
        KnownConstraints.build(space, [{"plugin": "lookup", "options": options}])
    assert message in str(info.value)


SOLVENTS = {"parameters": [
    {"name": "T", "type": "continuous", "low": 20.0, "high": 160.0},
    {"name": "solvent", "type": "categorical", "options": ["water", "ethanol", "toluene"],
     "descriptors": {"water": [100.0, 1.0], "ethanol": [78.4, 0.79], "toluene": [110.6, 0.87]},
     "descriptor_names": ["boiling_point", "density"]}],
    "objectives": [{"name": "y", "goal": "max"}]}
BOILING = {"water": 100.0, "ethanol": 78.4, "toluene": 110.6}


def test_a_constraint_names_a_categorical_descriptor_and_every_proposal_keeps_it():
    planner = Planner({**SOLVENTS, "constraints": ["T < boiling_point(solvent) - 5"]}, seed=0)
    for _ in range(4):
        for proposal in planner.ask(4):
            p = proposal.params
            assert p["T"] < BOILING[p["solvent"]] - 5
            planner.tell({**p, "y": p["T"] / 100.0, "experiment_id": proposal.experiment_id})
    # the share of the space below each boiling point (T uniform on [20, 160], the solvents equally likely)
    truth = np.mean([(b - 5 - 20.0) / 140.0 for b in BOILING.values()])
    fraction = planner.feasible_fraction
    assert abs(fraction.value - truth) < 4 * fraction.stderr + 1e-9
    with pytest.raises(ObservationError, match="violate"):
        planner.tell({"T": 90.0, "solvent": "ethanol", "y": 0.5})


@pytest.mark.parametrize("text, message", [
    ("T < boilng_point(solvent)", "no descriptor named 'boilng_point'.*did you mean 'boiling_point'"),
    ("T < boiling_point(T)", "boiling_point\\(\\) of anything but one categorical parameter"),
    ("T < melting_point(solvent)", "its descriptors are \\['boiling_point', 'density'\\]"),
    ("T < boiling_point(solvent, solvent)", "boiling_point\\(\\) of anything but one categorical parameter"),
])
def test_a_misnamed_descriptor_is_refused_naming_the_ones_there_are(text, message):
    with pytest.raises(ConfigError, match=message):
        Planner({**SOLVENTS, "constraints": [text]}, seed=0)


def test_descriptor_names_are_checked_when_the_config_loads():
    solvent = SOLVENTS["parameters"][1]
    for names, message in ((["boiling_point"], "1 descriptor name"), (["bp", "bp"], "duplicates"),
                           (["max", "density"], "functions of the constraint expressions"),
                           (["boiling point", "density"], "must be a list of names")):
        config = {**SOLVENTS, "parameters": [SOLVENTS["parameters"][0], {**solvent, "descriptor_names": names}]}
        with pytest.raises(ConfigError, match=message):
            Planner(config, seed=0)
