"""The hidden failing regions of benchmarks/failing_region.py: each region is what its docstring says (which optimum
lies inside, which outside), and "deep inside" means every point around fails."""

import pytest

from benchmarks.failing_region import REGIONS, best_feasible, deep, six_hump_camel

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


@pytest.mark.parametrize("region", list(REGIONS))
def test_deep_points_are_surrounded_by_failures(region):
    _, fails = REGIONS[region]
    found = 0
    for x0 in (0.02, 0.26, 0.51, 0.74, 0.98):
        for x1 in (0.02, 0.26, 0.51, 0.74, 0.98):
            if deep(fails, x0, x1):
                found += 1
                assert fails(x0, x1) and fails(x0 + 0.02, x1 - 0.02) and fails(x0 - 0.02, x1 + 0.02)
    assert found  # each region is a quarter: the middle of it is deep inside
    assert not deep(fails, 0.5, 0.5)  # on every region's edge
