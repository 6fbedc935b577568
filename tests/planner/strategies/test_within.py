"""Where an ask after an odd number of experiments runs the best result's combination of options, a GP of that
combination's own experiments decides where in it (`Planner._within`): the GP over every combination pools each
condition's effect across them."""

import numpy as np
import pytest

from gryffin_ros.planner import Planner
from gryffin_ros.planner.strategies import gryffin

CONFIG = {"name": "within", "parameters": [{"name": "c", "type": "categorical", "options": ["A", "B", "C"]},
                                           {"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                                           {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}],
          "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"}}


def value(c, x0, x1):
    """B and C are best at x0 = 0.2; A, better, at x0 = 0.85 (x1 = 0.5 for all)."""
    return (x0 - (0.85 if c == "A" else 0.2)) ** 2 + 0.3 * (x1 - 0.5) ** 2 - (0.12 if c == "A" else 0.0)


def proposal(seed, a_runs, known_constraints=None):
    """The next proposal after 14 random runs of B and C (those the known constraints allow) and `a_runs` of A (x0
    rising to 0.6), told in a random order (no combination settled)."""
    rng = np.random.default_rng(seed)
    runs = [(c, rng.random(), rng.random()) for c in ("B", "C") * 7]
    runs += [("A", x0, 0.5 + 0.1 * rng.standard_normal()) for x0 in a_runs]
    if known_constraints is not None:
        runs = [r for r in runs if known_constraints(dict(zip(("c", "x0", "x1"), r)))]
    planner = Planner(CONFIG, known_constraints=known_constraints, seed=seed)
    for i in rng.permutation(len(runs)):
        c, x0, x1 = runs[i]
        planner.tell({"c": c, "x0": x0, "x1": x1, "y": value(c, x0, x1)})
    (made,), _, _ = planner.draw(1)
    return made


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_best_combination_is_run_where_its_own_experiments_point(seed):
    """A's five experiments rise toward x0 = 0.6, the edge of what it has run; B's and C's fourteen peak at 0.2. The
    ask runs A, where A's own GP expects most: beyond 0.75 (0.82-0.87 on these seeds; the GP over every combination
    proposed 0.72-0.75 on seeds 0 to 2), and it says so."""
    made = proposal(seed, (0.1, 0.3, 0.45, 0.55, 0.6))
    assert made.params["c"] == "A" and "within" in made.meta
    assert made.params["x0"] > 0.75


def test_the_gp_of_one_combination_keeps_the_known_constraints():
    """With x0 + x1 <= 1.25 known, A's best (0.85, 0.5) is out of reach: the proposal stays on the allowed side."""
    made = proposal(1, (0.1, 0.3, 0.45, 0.55, 0.6), known_constraints=lambda p: p["x0"] + p["x1"] <= 1.25)
    assert made.params["c"] == "A" and "within" in made.meta
    assert made.params["x0"] + made.params["x1"] <= 1.25


def test_a_combination_with_too_few_experiments_gets_no_gp_of_its_own():
    """WITHIN_LEAST - 1 experiments on A (17 in all: an odd number)."""
    made = proposal(0, (0.3, 0.45, 0.6)[:gryffin.WITHIN_LEAST - 1])
    assert "within" not in made.meta


def test_every_other_ask_is_left_to_the_campaign_s_gp():
    """After an even number of experiments (here 20) the campaign's GP places the point itself: its expected
    improvement within the combination must be answered too, or it keeps choosing the combination (on a plateau with
    one good result, `test_on_a_plateau_with_one_good_combination_the_campaign_tries_others`)."""
    made = proposal(0, (0.1, 0.2, 0.3, 0.45, 0.55, 0.6))
    assert "within" not in made.meta


def test_a_combination_s_gp_keeps_to_fit_max_of_its_experiments():
    """400 experiments on one combination: its GP is fitted and conditioned on FIT_MAX of them, not on all 400 at
    n^3."""
    from gryffin_ros.planner.surrogates.gaussian_process import FIT_MAX

    rng = np.random.default_rng(0)
    planner = Planner(CONFIG, seed=0)
    for x0, x1 in rng.random((400, 2)):
        planner.tell({"c": "A", "x0": x0, "x1": x1, "y": value("A", x0, x1)})
    models = planner.surrogates()
    rows = np.ones(len(models.X), dtype=bool)
    gp = planner.surrogate_choice.local_gaussian_process(models.X, models.successful, models.descriptors, rows)
    assert len(gp.model.train_targets) == FIT_MAX
