"""The paper's discrete surfaces: feasible cells and constrained optima pinned (SPEC section 4)."""

import pytest

from gryffin_ros.benchmarks.surfaces import DISCRETE_SURFACES


@pytest.mark.parametrize("name, cells, optimum, value", [
    ("slope", 311, (0, 0), 0.0),
    ("sphere", 361, (10, 10), 0.0),
    ("michalewicz", 323, (14, 10), -1.8011),
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
