"""Linear inequalities recognized in expressions: exact chords for hit-and-run, exact boundary projection."""

import numpy as np
import pytest

from gryffin_ros.planner import KnownConstraints, SearchSpace
from gryffin_ros.planner.constraints.expressions import linear_inequalities
from gryffin_ros.planner.constraints.sampling import hit_and_run
from gryffin_ros.planner.optimizers.genetic import project_to_feasible

SPACE = SearchSpace.from_config([{"name": "F_C", "type": "continuous", "low": 10, "high": 200},
                                 {"name": "F_S", "type": "continuous", "low": 10, "high": 200},
                                 {"name": "solvent", "type": "categorical", "options": ["a", "b"]}])
CONTINUOUS = {"F_C", "F_S"}


@pytest.mark.parametrize("text, expected", [
    ("30 < F_C + F_S < 310", [({"F_C": -1.0, "F_S": -1.0}, -30.0), ({"F_C": 1.0, "F_S": 1.0}, 310.0)]),
    ("F_C <= 2 * F_S and F_S / 2 >= 5", [({"F_C": 1.0, "F_S": -2.0}, 0.0), ({"F_S": -0.5}, -5.0)]),
    ("F_C ** 2 < 100", None), ("F_C < 1 or F_S < 1", None), ("solvent == 'a'", None), ("F_C == 3", None),
    ("F_C * F_S < 5", None), ("1 < 2", None),
])
def test_linear_inequalities_are_recognized_exactly(text, expected):
    assert linear_inequalities(text, CONTINUOUS) == expected


def test_halfspaces_in_internal_units_agree_with_the_expression():
    constraints = KnownConstraints.build(SPACE, ["30 < F_C + F_S < 310", "F_C < 2 * F_S", "solvent == 'a'"])
    A, b, all_linear = constraints.halfspaces()
    assert not all_linear and A.shape == (3, 3) and (A[:, 2] == 0).all()
    X = SPACE.sample(np.random.default_rng(0), 2000)
    X[:, 2] = 0  # solvent 'a'
    assert ((X @ A.T <= b).all(axis=1) == constraints.feasible(X)).mean() > 0.999  # boundaries: measure zero


def test_hit_and_run_on_a_thin_polytope_never_needs_a_second_draw():
    space = SearchSpace.from_config([{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(3)])
    constraints = KnownConstraints.build(space, ["x0 + x1 + x2 <= 0.03"])  # 4.5e-6 of the cube
    calls = []
    original = constraints.feasible
    constraints.feasible = lambda X: (calls.append(len(X)), original(X))[1]
    X = hit_and_run(constraints, np.random.default_rng(1), np.array([[0.001, 0.001, 0.001]]), 3000, steps=3000)
    assert original(X).all()
    assert len(calls) == 3000  # one feasibility check per step: the first draw on every chord is feasible
    # uniform on the simplex {x >= 0, sum <= 0.03}: each coordinate has mean 0.03 / 4
    assert np.allclose(X[500:].mean(axis=0), 0.0075, atol=0.0012)


def test_genetic_projection_lands_exactly_on_a_linear_boundary():
    space = SearchSpace.from_config([{"name": "a", "type": "continuous", "low": 0, "high": 10},
                                     {"name": "b", "type": "continuous", "low": 0, "high": 10}])
    constraints = KnownConstraints.build(space, ["a + 2 * b <= 8"])
    parents = np.array([[0.1, 0.1], [0.2, 0.05]])
    children = np.array([[0.9, 0.9], [0.95, 0.5]])
    projected = project_to_feasible(constraints, children, parents)
    assert constraints.feasible(projected).all()
    users = projected * 10
    assert np.allclose(users[:, 0] + 2 * users[:, 1], 8.0, atol=1e-6)  # bisection alone stops 1 % short
    direction = (children - parents) / np.linalg.norm(children - parents, axis=1, keepdims=True)
    moved = (projected - parents) / np.linalg.norm(projected - parents, axis=1, keepdims=True)
    assert np.allclose(direction, moved)  # along the parent -> child segment
