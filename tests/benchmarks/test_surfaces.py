"""The paper's eight surfaces: feasible fractions and constrained optima pinned (SPEC section 4), constraints as the SI
prints them, and the vectorized constraint agreeing with the point-wise one."""

import numpy as np
import pytest

from benchmarks.surfaces import CAMEL_INFEASIBLE, CONTINUOUS_SURFACES, DISCRETE_SURFACES, SURFACES
from gryffin_ros.planner import KnownConstraints, SearchSpace


@pytest.mark.parametrize("name, cells, optimum, value", [
    ("slope", 311, (0, 0), 0.0),
    ("sphere", 361, (10, 10), 0.0),
    ("michalewicz", 323, (14, 10), -1.8011),
    ("camel", 347, (13, 9), 3.29882),
])
def test_feasible_cells_and_constrained_optimum(name, cells, optimum, value):
    surface = DISCRETE_SURFACES[name]
    assert len(surface.cells()) == cells
    assert surface.optimum() == optimum
    assert surface.objective(*optimum) == pytest.approx(value, abs=1e-4)


def test_constraints_exclude_what_the_paper_excludes():
    assert not DISCRETE_SURFACES["sphere"].feasible(9, 3) and not DISCRETE_SURFACES["sphere"].feasible(3, 11)
    assert not DISCRETE_SURFACES["slope"].feasible(3, 3)  # 9 + 9 = 18 in (5, 25)
    assert not DISCRETE_SURFACES["michalewicz"].feasible(14, 4)  # 12.5 < x0 < 15.5 and x1 < 5.5
    assert len(CAMEL_INFEASIBLE) == 94 and {(7, 11), (7, 15), (13, 5)} <= CAMEL_INFEASIBLE


def test_camel_unconstrained_minima_are_the_excluded_ones():
    camel = DISCRETE_SURFACES["camel"]
    ranked = sorted(((i, j) for i in range(21) for j in range(21)), key=lambda c: camel.objective(*c))
    assert (7, 11) in ranked[:2]  # the other global minimum, removed by the constraint
    assert ranked.index((13, 9)) < 4


@pytest.mark.parametrize("name, fraction, location, value", [
    ("branin", 0.722, (0.5425, 0.1517), 0.3979),
    ("dejong", 0.543, None, 1.0),
    ("schwefel", 0.541, (0.9210, 0.9210), -837.966),
    ("discreteackley", 0.777, (0.49, 0.49), 0.0),
    ("discreteackley_sum", 0.955, (0.49, 0.49), 0.0),
])
def test_continuous_feasible_fraction_and_constrained_optimum(name, fraction, location, value):
    surface = CONTINUOUS_SURFACES[name]
    assert surface.feasible_fraction() == pytest.approx(fraction, abs=1e-3)
    point, best = surface.constrained_optimum
    assert best == pytest.approx(value, abs=1e-3)
    if location is not None:
        assert point == pytest.approx(location, abs=2e-3)
    assert surface.is_feasible({"x0": point[0], "x1": point[1]})


def test_branin_constraint_removes_two_of_three_global_minima():
    branin = CONTINUOUS_SURFACES["branin"]
    minima = [((-np.pi + 5) / 15, 12.275 / 15), ((np.pi + 5) / 15, 2.275 / 15), ((9.42478 + 5) / 15, 2.475 / 15)]
    for x0, x1 in minima:
        assert branin.evaluate({"x0": x0, "x1": x1}) == pytest.approx(0.397887, abs=1e-5)
    assert [branin.is_feasible({"x0": x0, "x1": x1}) for x0, x1 in minima] == [False, True, False]


def test_dejong_minimum_itself_is_infeasible():
    dejong = CONTINUOUS_SURFACES["dejong"]
    assert dejong.evaluate({"x0": 0.5, "x1": 0.5}) == 0.0
    assert not dejong.is_feasible({"x0": 0.5, "x1": 0.5})


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_vectorized_constraint_agrees_with_pointwise_feasibility(name):
    surface = SURFACES[name]
    space = SearchSpace.from_config(surface.config()["parameters"])
    constraints = KnownConstraints.build(space, callables=surface.constraint)
    X = space.sample(np.random.default_rng(3), 400)
    batch = constraints.feasible(X)
    single = [surface.is_feasible(p) for p in space.to_params(X)]
    assert batch.tolist() == single
    assert 0 < batch.sum() < len(X)
