"""A stalled campaign whose best result and most of its last experiments sit on a bound of a continuous condition runs
its next experiment in the other half of that condition's range (`Planner._on_bound`, `Planner._released`): the GP
that led it there extrapolates the trend along the bound and never pays for the move that several conditions would
have to make together (benchmarks/README.md, round thirty-three)."""

import numpy as np
import pytest

from gryffin_ros.planner import Planner
from gryffin_ros.planner.strategies.stall import SETTLE_LEAST, STALL_WINDOW

CONFIG = {"name": "off_bound", "parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 10.0}
                                              for i in range(3)],
          "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"}}


def value(x0, x1, x2):
    """Better toward x0 = 10 (its upper bound), best at x1 = x2 = 5 there."""
    return -x0 / 10.0 + ((x1 - 5.0) / 10.0) ** 2 + ((x2 - 5.0) / 10.0) ** 2


def campaign(seed, on_bound=STALL_WINDOW, improving=False, known_constraints=None):
    """16 experiments (x0 in 6-10, the fourth the best, at x0 = 10), then STALL_WINDOW more, `on_bound` of them at
    x0 = 10 and worse than the best (the last one better than it if `improving`) -> the planner told them, in that
    order (the campaign stalled after 16 and after 24 experiments)."""
    rng = np.random.default_rng(seed)
    runs = []
    while len(runs) < 15:
        x = (6.0 + 4.0 * rng.random(), 10.0 * rng.random(), 10.0 * rng.random())
        if known_constraints is None or known_constraints(dict(zip(("x0", "x1", "x2"), x))):
            runs.append(x)
    runs.insert(3, (10.0, 5.0, 5.0))  # the best result, on the bound
    for i in range(STALL_WINDOW):
        x0 = 10.0 if i < on_bound else 6.0 + 3.0 * rng.random()
        runs.append((x0, 5.0 + rng.choice([-1.0, 1.0]) * (1.0 + 3.0 * rng.random()), 10.0 * rng.random()))
    if improving:
        runs[-1] = (10.0, 5.0, 5.2)
        runs[runs.index((10.0, 5.0, 5.0))] = (10.0, 3.0, 5.0)
    planner = Planner(CONFIG, known_constraints=known_constraints, seed=seed)
    for x0, x1, x2 in runs:
        planner.tell({"x0": x0, "x1": x1, "x2": x2, "y": value(x0, x1, x2)})
    return planner


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_stalled_campaign_on_a_bound_runs_the_other_half_of_its_range(seed):
    """Every one of the last 8 experiments ran x0 = 10, none improved on the best (also at 10): the next one runs x0
    in 0-5, and says so."""
    (made,), _, _ = campaign(seed).draw(1)
    assert "stalled" in made.meta and "off_bound" in made.meta
    assert made.params["x0"] <= 5.0


def test_the_move_off_the_bound_keeps_the_known_constraints():
    """With x0 + x1 >= 8 known (in the lower half of x0's range, x1 = 5 only from x0 = 3 on), the move keeps to it."""
    def allowed(p):
        return p["x0"] + p["x1"] >= 8.0

    planner = campaign(0, known_constraints=allowed)
    (made,), _, _ = planner.draw(1)
    assert "off_bound" in made.meta and made.params["x0"] <= 5.0
    assert allowed(made.params)


def test_fewer_than_settle_least_on_the_bound_leave_the_ask_to_the_gp():
    (made,), _, _ = campaign(0, on_bound=SETTLE_LEAST - 1).draw(1)
    assert "off_bound" not in made.meta


def test_a_campaign_that_improved_is_not_moved_off_its_bound():
    """The last experiment improved on the best: no stall, no move."""
    (made,), _, _ = campaign(0, improving=True).draw(1)
    assert "stalled" not in made.meta and "off_bound" not in made.meta
