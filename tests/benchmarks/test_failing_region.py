"""The hidden failing regions of benchmarks/failing_region.py: each region is what its docstring says (which optimum
lies inside, which outside), and "deep inside" means every point around fails."""

import pytest

from benchmarks.failing_region import REGIONS, best_feasible, deep, failure_draws, himmelblau, six_hump_camel, wavy_bowl

CAMEL_MINIMUM = -1.031628  # the six-hump camel's global minimum, at (+-0.0898, -+0.7126) in its own coordinates


def test_the_camel_region_holds_one_global_minimum_and_leaves_the_other_feasible():
    f, fails = REGIONS["camel"]
    inside, outside = ((0.0898 + 3) / 6, (-0.7126 + 2) / 4), ((-0.0898 + 3) / 6, (0.7126 + 2) / 4)
    # the minimum's coordinates, printed to 4 digits, give a value within 1e-6 of it (1e-5 allowed)
    assert f(*inside) == pytest.approx(CAMEL_MINIMUM, abs=1e-5) and fails(*inside)
    assert f(*outside) == pytest.approx(CAMEL_MINIMUM, abs=1e-5) and not fails(*outside)
    assert six_hump_camel(0.5, 0.5) == 0.0  # the origin of its own coordinates
    # the best feasible grid value is the feasible minimum, up to the grid's spacing (1e-3: a change of ~1e-5)
    assert best_feasible("camel", steps=1001) == pytest.approx(CAMEL_MINIMUM, abs=1e-4)


def test_camel_open_never_fails_and_random_failures_come_at_their_rate_whatever_the_proposals():
    _, fails = REGIONS["camel-open"]
    assert not any(fails(x0 / 10, x1 / 10) for x0 in range(11) for x1 in range(11))
    assert best_feasible("camel-open", steps=1001) == pytest.approx(CAMEL_MINIMUM, abs=1e-4)
    assert failure_draws(3, 0.3) == failure_draws(3, 0.3) != failure_draws(4, 0.3)
    assert not any(failure_draws(3, 0.0))
    # 10 000 draws at 0.3: the share's standard deviation is 0.0046; 0.02 is over four of them
    assert sum(failure_draws(0, 0.3, 10_000)) / 10_000 == pytest.approx(0.3, abs=0.02)


def test_the_himmelblau_region_holds_one_of_its_four_minima():
    _, fails = REGIONS["himmelblau"]
    minima = [(0.8, 0.7), (0.2195, 0.8131), (0.1221, 0.1717), (0.8584, 0.3152)]
    # the minima's coordinates to 4 digits give values within 1e-6 of 0 (1e-5 allowed)
    assert all(himmelblau(*m) == pytest.approx(0.0, abs=1e-5) for m in minima)
    assert [fails(*m) for m in minima] == [True, False, False, False]
    assert himmelblau(0.5, 0.5) > 1.0  # the square's middle is far from every minimum
    # the best feasible grid value is a feasible minimum, up to the grid's spacing (1e-3: a change below 1e-4)
    assert best_feasible("himmelblau", steps=1001) == pytest.approx(0.0, abs=1e-4)


def test_the_disc_leaves_the_bowls_minimum_just_outside_and_the_diagonal_holds_its_optimum():
    _, disc = REGIONS["disc"]
    minimum = (0.593, 0.45)
    # the bowl's minimum is 0.008 outside the disc: a step of 0.01 towards the disc's centre fails
    assert not disc(*minimum) and disc(minimum[0] - 0.01, minimum[1] - 0.006)
    assert all(wavy_bowl(*minimum) < wavy_bowl(minimum[0] + a, minimum[1] + b)
               for a in (-0.01, 0.0, 0.01) for b in (-0.01, 0.0, 0.01) if a or b)
    assert best_feasible("disc", steps=1001) == pytest.approx(wavy_bowl(*minimum), abs=1e-4)
    f, diagonal = REGIONS["diagonal"]
    assert diagonal(0.6, 0.5) and f(0.6, 0.5) == 0.0  # the unconstrained optimum fails
    # the best feasible value is on the edge x0 + x1 = 1, at (0.5333, 0.4667): 1/150
    assert best_feasible("diagonal", steps=1001) == pytest.approx(1 / 150, abs=1e-4)
    assert not diagonal(0.5333, 0.4667) and diagonal(0.5333 + 0.001, 0.4667 + 0.001)


@pytest.mark.parametrize("region", [r for r in REGIONS if r != "camel-open"])
def test_deep_points_are_surrounded_by_failures(region):
    _, fails = REGIONS[region]
    found = 0
    for x0 in (0.02, 0.26, 0.51, 0.74, 0.98):
        for x1 in (0.02, 0.26, 0.51, 0.74, 0.98):
            if deep(fails, x0, x1):
                found += 1
                assert fails(x0, x1) and fails(x0 + 0.02, x1 - 0.02) and fails(x0 - 0.02, x1 + 0.02)
    assert found  # every region holds a point of this 5 x 5 grid deep inside
    assert not deep(fails, 0.5, 0.5)  # on every region's edge
