"""Chimera scalarization against hand-computed merits, and the flow-reactor hierarchy of the paper."""

import numpy as np
import pytest

from gryffin_ros.planner import Planner
from gryffin_ros.planner.chimera import Chimera
from gryffin_ros.planner.config import Objective


def test_hand_computed_merits_with_relative_tolerances():
    # normalized f1 = [0, .25, .55, 1], f2 = [1, 1/3, 0, .8]; T1 = 0.5 keeps points 0 and 1; among them
    # T2 = 1/3 + 0.5 * (1 - 1/3) = 2/3 keeps point 1. Worked through the shifts: [0.5, 1/6, 0.55, 1] -> rescaled.
    chimera = Chimera([Objective("a", "min", 0.5), Objective("b", "min", 0.5)], softness=0.0)
    merits = chimera.merits(np.array([[0.0, 3.0], [1.0, 1.0], [2.2, 0.0], [4.0, 2.4]]))
    assert merits == pytest.approx([0.4, 0.0, 0.46, 1.0])


def test_soft_steps_approach_the_hard_ones():
    values = np.array([[0.0, 3.0], [1.0, 1.0], [2.2, 0.0], [4.0, 2.4]])
    objectives = [Objective("a", "min", 0.5), Objective("b", "min", 0.5)]
    hard = Chimera(objectives, softness=0.0).merits(values)
    assert Chimera(objectives, softness=1e-3).merits(values) == pytest.approx(hard, abs=1e-6)


FLOW = [Objective("X1_X2", "max", 0.9, absolute=True), Objective("cost", "min")]


def test_flow_reactor_hierarchy_cheaper_above_0_9_higher_yield_below():
    names = ["A", "B", "C", "D", "E", "F"]
    values = np.array([
        [0.95, 0.010],   # A: above 0.9
        [0.92, 0.005],   # B: above 0.9, cheaper than A
        [0.85, 0.001],   # C: below, cheap
        [0.80, 0.0005],  # D: below, cheapest, lowest yield
        [0.88, 0.020],   # E: below, highest yield of those below
        [0.91, 0.015],   # F: above 0.9, the most expensive of those
    ])
    merits = Chimera(FLOW).merits(values)
    ranking = [names[i] for i in np.argsort(merits)]
    assert ranking == ["B", "A", "F", "E", "C", "D"]
    assert merits.min() == 0.0 and merits.max() == 1.0


def test_single_point_and_ties_give_finite_merits():
    assert Chimera(FLOW).merits(np.array([[0.9, 0.01]])).tolist() == [0.0]
    assert np.isfinite(Chimera(FLOW).merits(np.array([[0.5, 0.01], [0.5, 0.01]]))).all()


def test_planner_uses_chimera_for_best_and_merits():
    config = {"parameters": [{"name": "F_C", "type": "continuous", "low": 0, "high": 200},
                             {"name": "F_S", "type": "continuous", "low": 0, "high": 200}],
              "objectives": [{"name": "X1_X2", "goal": "max", "tolerance": 0.9, "absolute": True},
                             {"name": "cost", "goal": "min"}]}
    planner = Planner(config, seed=0)
    planner.tell([{"F_C": 10.0, "F_S": 10.0, "X1_X2": 0.95, "cost": 0.02},
                  {"F_C": 20.0, "F_S": 10.0, "X1_X2": 0.93, "cost": 0.01},
                  {"F_C": 30.0, "F_S": 10.0, "X1_X2": 0.85, "cost": 0.001}])
    assert planner.best().params == {"F_C": 20.0, "F_S": 10.0}
    for proposal in planner.ask(2):
        assert set(proposal.params) == {"F_C", "F_S"}


def test_the_best_kept_as_observations_arrive_is_the_best_of_all_of_them():
    """Planner.best() keeps the successful observations' values as they arrive instead of collecting them from every
    record on each call; whatever the order of arrival and the failures among them, it is the best of all."""
    from gryffin_ros.planner.merit import best_of
    config = {"parameters": [{"name": "x", "type": "continuous", "low": 0, "high": 1}],
              "objectives": [{"name": "X1_X2", "goal": "max", "tolerance": 0.9, "absolute": True},
                             {"name": "cost", "goal": "min"}]}
    rng = np.random.default_rng(3)
    planner = Planner(config, seed=0)
    assert planner.best() is None
    for _ in range(12):  # relative ranges move as data arrive: the best can change to an earlier observation
        rows = [{"x": float(x), "X1_X2": float(y) if rng.random() > 0.2 else None, "cost": float(c)}
                for x, y, c in zip(rng.random(5), rng.uniform(0.5, 1.0, 5), rng.uniform(0.001, 0.01, 5))]
        planner.tell(rows)
        assert planner.best() is best_of(planner.config, planner.observations)
    restored = Planner(config, seed=0, history=planner.history.snapshot())
    assert restored.best() is best_of(planner.config, planner.observations)
    assert len(planner.successful_values()[0]) == sum(not o.failed for o in planner.observations)
