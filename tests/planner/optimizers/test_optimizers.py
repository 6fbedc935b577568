"""The constrained acquisition optimizers: Adam's steps are projected onto linear constraints and stop at the last
feasible point of others, Hill keeps feasibility, the genetic optimizer projects infeasible children onto the
boundary."""

import numpy as np
import torch

from gryffin_ros.planner import KnownConstraints, SearchSpace
from gryffin_ros.planner.acquisition.kernel import Acquisition
from gryffin_ros.planner.optimizers.adam_hill import AdamHillOptimizer
from gryffin_ros.planner.optimizers.genetic import GeneticOptimizer, project_to_feasible
from gryffin_ros.planner.surrogates.kernel_density import KernelDensity

SQUARE = SearchSpace.from_config([{"name": "x0", "type": "continuous", "low": 0, "high": 1},
                                  {"name": "x1", "type": "continuous", "low": 0, "high": 1}])


def acquisition_pulling_to(space, best, strategy=1.0):
    """An exploitation acquisition whose minimum is the observation `best` (merit 0); broad kernels (n = 3)."""
    X = np.array([best, [0.1, 0.9], [0.9, 0.1]])
    density = KernelDensity(space, X, np.array([0.0, 1.0, 1.0]), 1.0, torch.Generator().manual_seed(0))
    return Acquisition(density, strategy)


def test_adam_stops_at_the_last_feasible_position_of_a_nonlinear_constraint():
    constraints = KnownConstraints.build(SQUARE, ["x0 ** 2 < 0.25"])  # x0 < 0.5, but not linear: no projection
    assert constraints.halfspaces() is None
    acquisition = acquisition_pulling_to(SQUARE, [0.56, 0.5])
    start = np.array([[0.49, 0.5], [0.45, 0.52], [0.3, 0.5]])
    refined, alpha = AdamHillOptimizer(constraints, steps=30).optimize(acquisition, start, np.random.default_rng(0))
    assert constraints.feasible(refined).all()
    assert (refined[:2, 0] > 0.48).all()  # pushed towards the optimum until the boundary stopped them
    assert np.allclose(alpha, acquisition.evaluate(refined))


def test_adam_slides_along_a_linear_boundary_towards_the_constrained_optimum():
    # the acquisition's minimum (0.7, 0.5) is outside x0 + x1 <= 1; on the line the best point is near (0.6, 0.4)
    constraints = KnownConstraints.build(SQUARE, ["x0 + x1 <= 1"])
    acquisition = acquisition_pulling_to(SQUARE, [0.7, 0.5])
    start = np.array([[0.2, 0.8]])  # on the boundary: every gradient step leaves the set
    refined, alpha = AdamHillOptimizer(constraints, steps=30).optimize(acquisition, start, np.random.default_rng(0))
    assert constraints.feasible(refined).all()
    assert refined[0].sum() > 0.99  # it stayed on the boundary
    assert refined[0, 0] > 0.35  # and moved along it (a stopped point would stay at 0.2)
    assert alpha[0] < acquisition.evaluate(start)[0]
    assert np.allclose(alpha, acquisition.evaluate(refined))


def test_a_projected_step_that_breaks_a_nonlinear_constraint_is_not_taken():
    # along x0 + x1 = 1 towards (0.6, 0.4), the centre of a keep-out disc on the line: the point slides up to the disc
    constraints = KnownConstraints.build(SQUARE, ["x0 + x1 <= 1", "(x0 - 0.6) ** 2 + (x1 - 0.4) ** 2 >= 0.01"])
    acquisition = acquisition_pulling_to(SQUARE, [0.7, 0.5])
    start = np.array([[0.4, 0.6]])
    refined, alpha = AdamHillOptimizer(constraints, steps=30).optimize(acquisition, start, np.random.default_rng(0))
    assert constraints.feasible(refined).all()
    assert refined[0].sum() > 0.99 and refined[0, 0] > 0.45  # on the line, and moved along it
    assert np.allclose(alpha, acquisition.evaluate(refined))


def test_adam_improves_the_acquisition_without_constraints_binding():
    constraints = KnownConstraints(SQUARE)
    acquisition = acquisition_pulling_to(SQUARE, [0.5, 0.5])
    start = np.array([[0.52, 0.49], [0.47, 0.53]])
    before = acquisition.evaluate(start)
    refined, alpha = AdamHillOptimizer(constraints).optimize(acquisition, start, np.random.default_rng(0))
    assert (alpha < before).all()


def test_hill_moves_only_to_feasible_better_options():
    space = SearchSpace.from_config([{"name": "n", "type": "discrete", "low": 0, "high": 9},
                                     {"name": "c", "type": "categorical", "options": ["a", "b", "c"]}])
    constraints = KnownConstraints.build(space, ["n <= 6"])
    X = np.array([[8.0, 0.0], [2.0, 1.0]])  # the best observation (merit 0) is infeasible now at n = 8
    density = KernelDensity(space, X, np.array([0.0, 1.0]), 1.0, torch.Generator().manual_seed(0))
    acquisition = Acquisition(density, 1.0)
    start = np.array([[3.0, 2.0]] * 40)
    refined, alpha = AdamHillOptimizer(constraints).optimize(acquisition, start, np.random.default_rng(1))
    assert constraints.feasible(refined).all()
    assert alpha.min() < acquisition.evaluate(start).min()
    assert (refined[:, 0] <= 6).all()


def test_projection_lands_within_one_percent_of_the_boundary():
    constraints = KnownConstraints.build(SQUARE, ["x0 + x1 <= 1"])
    parents = np.array([[0.2, 0.2], [0.1, 0.6]])
    children = np.array([[0.9, 0.9], [0.9, 0.6]])
    projected = project_to_feasible(constraints, children, parents)
    assert constraints.feasible(projected).all()
    assert (projected.sum(axis=1) > 0.97).all()


def test_projection_tries_parent_categories_first_then_restores_the_childs():
    space = SearchSpace.from_config([{"name": "x", "type": "continuous", "low": 0, "high": 1},
                                     {"name": "c", "type": "categorical", "options": ["safe", "hot"]}])
    constraints = KnownConstraints.build(space, ["x < 0.5 if c == 'hot' else x < 0.9"])
    # (i) parent's category makes the child feasible as it is
    out = project_to_feasible(constraints, np.array([[0.7, 1.0]]), np.array([[0.2, 0.0]]))
    assert out.tolist() == [[0.7, 0.0]]
    # (ii)+(iii) bisection, then the child's own category kept when feasible at the projected point
    out = project_to_feasible(constraints, np.array([[0.95, 1.0]]), np.array([[0.3, 1.0]]))
    assert constraints.feasible(out).all() and out[0, 1] == 1.0 and 0.48 < out[0, 0] < 0.5


def test_genetic_population_stays_feasible_and_improves():
    constraints = KnownConstraints.build(SQUARE, ["(x0 - 0.5) ** 2 + (x1 - 0.5) ** 2 > 0.01"])
    acquisition = acquisition_pulling_to(SQUARE, [0.62, 0.5])
    rng = np.random.default_rng(0)
    start = SQUARE.sample(rng, 400)
    start = start[constraints.feasible(start)]
    final, alpha = GeneticOptimizer(constraints).optimize(acquisition, start, rng)
    assert constraints.feasible(final).all()
    assert len(final) == len(start)
    assert alpha.min() <= acquisition.evaluate(start).min()
    assert np.allclose(alpha, acquisition.evaluate(final))


def test_adam_refines_only_the_most_promising_start_points():
    constraints = KnownConstraints.build(SQUARE, ["x0 + x1 < 1.5"])
    acquisition = acquisition_pulling_to(SQUARE, [0.5, 0.5])
    start = np.random.default_rng(4).random((1000, 2)) * 0.7
    before = acquisition.evaluate(start)
    refined, alpha = AdamHillOptimizer(constraints).optimize(acquisition, start, np.random.default_rng(0))
    moved = (refined != start).any(axis=1)
    assert 0 < moved.sum() <= 100  # the best 10 % at most
    assert before[moved].max() <= np.sort(before)[99]  # and only from among the best 10 % by their start value
    assert np.allclose(alpha, acquisition.evaluate(refined)) and constraints.feasible(refined).all()
    assert alpha.min() < before.min()
