"""The hidden failing regions of benchmarks/failing_region.py: each region is what its docstring says (which optimum
lies inside, which outside), and "deep inside" means every point around fails."""

import pytest

from benchmarks.failing_region import REGIONS, best_feasible, deep, failure_draws, six_hump_camel

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


@pytest.mark.parametrize("region", [r for r in REGIONS if r != "camel-open"])
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
