"""The flow-reactor BNN emulator against the measured data it was trained on."""

import csv
from pathlib import Path

import numpy as np
import pytest

from gryffin_ros.emulators import FlowReactorEmulator
from gryffin_ros.emulators.flow_reactor import reagent_cost
from gryffin_ros.planner import ConfigError, KnownConstraints, SearchSpace

DATA = Path(__file__).resolve().parents[1] / "data" / "fullerenes_emulator_data.csv"


def held_out_rows():
    """The paper's split: shuffle with np.random.seed(42), train on the first 500 rows, test on the last 100."""
    with open(DATA) as handle:
        rows = np.array([[float(v) for v in row.values()] for row in csv.DictReader(handle)])
    np.random.seed(42)
    order = np.arange(len(rows))
    np.random.shuffle(order)
    return rows[order[500:]]


def test_mean_prediction_correlates_with_measured_fractions():
    test = held_out_rows()
    assert len(test) == 100
    mean = FlowReactorEmulator(seed=0).predict(test[:, :3], passes=200).mean(axis=0)
    for j, name in enumerate(("X0", "X1", "X2", "X3")):
        r = np.corrcoef(mean[:, j], test[:, 3 + j])[0, 1]
        assert r >= 0.9, f"{name}: Pearson {r:.3f}"


def test_one_experiment_is_one_stochastic_pass_with_cost():
    emulator = FlowReactorEmulator(seed=1)
    first, second = emulator.run(100.0, 120.0, 140.0), emulator.run(100.0, 120.0, 140.0)
    assert first != second  # weights are drawn anew for each experiment
    for result in (first, second):
        fractions = [result.x0, result.x1, result.x2, result.x3]
        assert all(0 <= f <= 1 for f in fractions) and sum(fractions) == pytest.approx(1.0)
        assert result.yield_x1_x2 == pytest.approx(result.x1 + result.x2)
        assert result.cost == pytest.approx(1e-6 * (168.8 * 100 + 2.674 * 120))
    assert reagent_cost(0.0, 100.0) == pytest.approx(2.674e-4)


def test_same_seed_same_experiments():
    a, b = FlowReactorEmulator(seed=5), FlowReactorEmulator(seed=5)
    assert [a.run(50, 60, 120) for _ in range(3)] == [b.run(50, 60, 120) for _ in range(3)]


# ---- the reactor's constraint plugin (registered by this package under gryffin_ros.constraints) ---------------
def test_flow_reactor_plugin_uses_configurable_bounds():
    space = SearchSpace.from_config([{"name": "F_C", "type": "continuous", "low": 0, "high": 200},
                                     {"name": "F_S", "type": "continuous", "low": 0, "high": 200}])
    c = KnownConstraints.build(space, [{"plugin": "flow_reactor", "options": {"min_total": 10}}])
    assert c.is_feasible({"F_C": 10.0, "F_S": 10.0})
    assert not c.is_feasible({"F_C": 3.0, "F_S": 4.0})
    assert not c.is_feasible({"F_C": 150.0, "F_S": 170.0})  # total above 310
    assert not c.is_feasible({"F_C": 100.0, "F_S": 40.0})  # F_C >= 2 F_S
    default = KnownConstraints.build(space, [{"plugin": "flow_reactor"}])
    assert not default.is_feasible({"F_C": 10.0, "F_S": 10.0})  # total 20 <= 30


@pytest.mark.parametrize("options, message", [
    ({"max_flow": 3}, "unknown option(s) ['max_flow']"),
    ({"min_total": 400}, "must be below max_total"),
    ({"c60_flow": "F_X"}, "'c60_flow' must name a continuous parameter"),
    ({"c60_flow": "F_S"}, "must be two parameters"),
])
def test_flow_reactor_plugin_options_are_checked_at_load(options, message):
    space = SearchSpace.from_config([{"name": "F_C", "type": "continuous", "low": 0, "high": 200},
                                     {"name": "F_S", "type": "continuous", "low": 0, "high": 200}])
    with pytest.raises(ConfigError) as info:
        KnownConstraints.build(space, [{"plugin": "flow_reactor", "options": options}])
    assert message in str(info.value)
