"""Stalled and settled campaigns: the rules that say when, and the GP asks that follow (untried regions at the results'
mean; another combination of options)."""

import numpy as np
import pytest

from gryffin_ros.planner import Planner
from gryffin_ros.planner.strategies.stall import (
    SETTLE_LEAST,
    STALL_TOLERANCE,
    STALL_WINDOW,
    exploring_until,
    settled,
    stall,
)
from gryffin_ros.planner.surrogates.gaussian_process import GaussianProcess


def stalled_asks(merits, **kwargs):
    """The numbers of experiments after which the ask is a stalled one."""
    return [m for m in range(1, len(merits) + 1) if stall(np.asarray(merits[:m], dtype=float), **kwargs) is not None]


def test_a_campaign_stalls_after_a_window_without_improvement_once_per_window():
    flat = [1.0, 0.5] + [0.2] * 30
    # from 2 windows on; then again a window later while nothing improves
    assert stalled_asks(flat) == [2 * STALL_WINDOW, 3 * STALL_WINDOW, 4 * STALL_WINDOW]
    assert stall(np.array(flat[:2 * STALL_WINDOW])) == 0.0
    improving = np.linspace(1.0, 0.0, 40)  # every experiment better than the last
    assert stalled_asks(improving) == []
    # an improvement of 2 % of the range inside the window is not a stall; 0.5 % is
    for step, stalls in ((2 * STALL_TOLERANCE, False), (STALL_TOLERANCE / 2, True)):
        merits = [1.0, 0.0] + [0.5] * 12 + [-step] + [0.5] * 1
        assert (stall(np.array(merits)) is not None) is stalls
    # an improvement (experiment 17) ends a stall: the next is a whole window after it
    assert stalled_asks([1.0] + [0.5] * 15 + [0.0] + [0.4] * 15) == [16, 25]


def test_experiments_that_explored_options_on_purpose_start_no_stall():
    flat = [0.0] + [0.5] * 30
    assert stalled_asks(flat, since=20) == [28]  # a whole window after the exploring ones
    # ligand and solvent of each experiment: the 2nd run of solvent 2 is experiment 6, the 2nd of ligand 3 the 5th
    options = np.array([[0, 0], [1, 1], [0, 2], [3, 1], [3, 0], [1, 2], [0, 0], [1, 1]])
    assert exploring_until(options, tries=2) == 6
    assert exploring_until(options, tries=1) == 4  # ligand 3 first ran in experiment 4
    assert exploring_until(np.empty((8, 0)), tries=2) == 0  # no such parameter


def test_failed_experiments_improve_nothing_and_without_an_earlier_success_nothing_has_stalled():
    nan = float("nan")
    assert stalled_asks([0.0] + [nan] * 15) == [16]
    assert stalled_asks([nan] * 10 + [0.3] * 6) == []  # nothing succeeded before the last window
    assert stalled_asks([nan] * 20) == []


def test_a_stalled_ask_predicts_what_the_campaign_has_not_tried_at_the_results_mean():
    """Most results on a plateau (nothing reacted: 1.0), a few good ones at one corner: the fitted constant mean sits
    near the plateau, so far from every experiment the GP predicts the plateau. At the results' mean it predicts the
    mean of the results there instead; near the experiments the data decide as before."""
    rng = np.random.default_rng(0)
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(3)],
              "objectives": [{"name": "y", "goal": "min"}]}
    space = Planner(config, seed=0).space
    plateau, good = rng.uniform(0.0, 0.3, (16, 3)), 0.05 + 0.1 * rng.random((8, 3))
    y = np.concatenate([1.0 + 0.01 * rng.random(16), 0.1 + 0.2 * rng.random(8)])
    gp = GaussianProcess(space, np.concatenate([plateau, good]), y, seed=0)

    def predicted(points):  # standardized units (BoTorch's Standardize): 0 is the results' mean
        mean, _ = gp.posterior.mean_and_sigma(gp.features.of(points))
        return mean.detach().numpy()

    plateau_level = (1.0 - y.mean()) / y.std(ddof=1)  # 0.67
    far, near = np.array([[0.95, 0.95, 0.95]]), predicted(good)
    assert 0.3 * plateau_level < predicted(far)[0] < plateau_level  # the fitted constant: toward the plateau
    gp.at_results_mean()
    # within a tenth of a standard deviation: what the data 0.9 or more away still say there
    assert predicted(far)[0] == pytest.approx(0.0, abs=0.1)
    assert predicted(good) == pytest.approx(near, abs=0.1)  # beside the experiments the data decide as before


def test_a_planner_says_which_asks_followed_a_stall():
    config = {"parameters": [{"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                             {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0},
                             {"name": "x2", "type": "continuous", "low": 0.0, "high": 1.0}],
              "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"}}
    planner = Planner(config, seed=1)
    rng = np.random.default_rng(1)
    # the best result first, then 16 poorer ones: the ask after the 16th experiment is a stalled one, the next not
    results = [0.0] + list(1.0 + rng.random(2 * STALL_WINDOW))
    points = rng.random((len(results), 3))
    said = []
    for i, (point, value) in enumerate(zip(points, results)):
        planner.tell({"x0": point[0], "x1": point[1], "x2": point[2], "y": float(value)})
        if i + 1 >= 2 * STALL_WINDOW - 1:
            (proposal,), _, _ = planner.draw(1)
            said.append((i + 1, "stalled" in proposal.meta))
    assert said == [(15, False), (16, True), (17, False)]


def test_a_planner_counts_no_stall_while_options_were_being_explored():
    """16 results as above, but the third solvent ran for the first and second time in experiments 14 and 15: those
    explored it, so the ask after the 16th is no stalled one (it would be without the solvent)."""
    config = {"parameters": [{"name": "solvent", "type": "categorical", "options": ["A", "B", "C"]},
                             {"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                             {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}],
              "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"}}
    rng = np.random.default_rng(2)
    solvents = ["A", "B"] * 6 + ["A", "C", "C", "B"]
    results = [0.0] + list(1.0 + rng.random(15))
    planner = Planner(config, seed=2)
    for solvent, point, value in zip(solvents, rng.random((16, 2)), results):
        planner.tell({"solvent": solvent, "x0": point[0], "x1": point[1], "y": float(value)})
    (proposal,), _, _ = planner.draw(1)
    assert proposal.meta["surrogate"] == "gp" and "stalled" not in proposal.meta


def settled_asks(options):
    """The numbers of experiments after which the ask is a settled one."""
    return [m for m in range(1, len(options) + 1) if settled(np.asarray(options[:m])) is not None]


def test_a_campaign_settles_when_most_of_a_window_ran_one_combination_once_per_window():
    one = [[0, 1]] * 40
    assert settled_asks(one) == [2 * STALL_WINDOW, 3 * STALL_WINDOW, 4 * STALL_WINDOW, 5 * STALL_WINDOW]
    assert settled(np.array(one[:2 * STALL_WINDOW])).tolist() == [0, 1]
    # SETTLE_LEAST of the window's experiments in one combination settle it, one fewer does not
    varied = [[k % 3, k % 2] for k in range(2 * STALL_WINDOW)]  # no combination twice in a row
    for alike, settles in ((SETTLE_LEAST, True), (SETTLE_LEAST - 1, False)):
        options = varied[:-STALL_WINDOW] + [[4, 0]] * alike + varied[-(STALL_WINDOW - alike):]
        assert (settled(np.array(options)) is not None) is settles
        if settles:
            assert settled(np.array(options)).tolist() == [4, 0]
    assert settled_asks(varied) == []
    # one combination after 8 varied experiments: settled from the ask after the 16th on (no earlier: m >= 2 windows)
    assert settled_asks(varied[:8] + [[1, 1]] * 24) == [16, 24, 32]
    assert settled(np.empty((2 * STALL_WINDOW, 0))) is not None  # no categorical parameter: the caller's concern


CATALYST_LIGAND = {"parameters": [{"name": "catalyst", "type": "categorical", "options": ["A", "B", "C"]},
                                  {"name": "ligand", "type": "categorical", "options": ["p", "q"]},
                                  {"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0}],
                   "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"}}


def test_a_settled_campaign_runs_another_combination_and_says_so():
    """Each option run twice, then every experiment on catalyst A with ligand p, the results improving there: the GP's
    expected improvement stays on A / p; the ask after the 16th experiment runs the best result's conditions with one
    option changed."""
    rng = np.random.default_rng(3)
    first = [("A", "q"), ("B", "p"), ("C", "q"), ("B", "q"), ("C", "p"), ("A", "q"), ("B", "p"), ("C", "q")]
    runs = [(c, ligand, float(x), 1.0 + rng.random()) for (c, ligand), x in zip(first, rng.random(8))]
    runs += [("A", "p", 0.1 * k, 0.5 - 0.05 * k) for k in range(1, 9)]  # a crawl along x0 on A / p
    said = []
    for m in (15, 16):
        planner = Planner(CATALYST_LIGAND, seed=3)
        for catalyst, ligand, x, y in runs[:m]:
            planner.tell({"catalyst": catalyst, "ligand": ligand, "x0": x, "y": y})
        (proposal,), _, _ = planner.draw(1)
        said.append((m, "settled" in proposal.meta, (proposal.params["catalyst"], proposal.params["ligand"])))
    assert said[0][:2] == (15, False)
    assert said[1][:2] == (16, True) and said[1][2] != ("A", "p")
    # the best result's conditions (x0 = 0.8, its last experiment), one option changed
    assert sum(a != b for a, b in zip(said[1][2], ("A", "p"))) == 1
    assert proposal.params["x0"] == pytest.approx(0.8)


def settled_ask_after_a_crawl(first, seed):
    """The proposal of the ask after `first` (catalyst, ligand, x0, y; y with a little noise of `seed`) and a crawl
    on A / p along x0 up to 0.8, improving on every experiment."""
    rng = np.random.default_rng(seed)
    runs = [(c, ligand, x, y + 0.05 * rng.random()) for c, ligand, x, y in first]
    runs += [("A", "p", 0.1 * k, 0.5 - 0.05 * k) for k in range(1, 9)]  # the crawl
    planner = Planner(CATALYST_LIGAND, seed=seed)
    for catalyst, ligand, x, y in runs:
        planner.tell({"catalyst": catalyst, "ligand": ligand, "x0": x, "y": y})
    (proposal,), _, _ = planner.draw(1)
    return proposal


def test_a_settled_campaign_swaps_to_a_combination_it_has_not_run_first():
    """A crawl on A / p (x0 up to 0.8); B / p ran at small x0 as well as A / p did there, A / q at 0.8 worse, C only
    with q, poorly. The expected improvement of the swaps favours B / p at x0 = 0.8 (the trend along x0 carried
    over); B / p has been run, C / p has not: the settled ask runs C / p at the best result's conditions."""
    first = [("A", "q", 0.8, 0.3), ("B", "p", 0.1, 0.45), ("C", "q", 0.2, 3.0), ("B", "p", 0.2, 0.4),
             ("C", "q", 0.8, 3.0), ("A", "q", 0.4, 0.6), ("B", "q", 0.3, 1.5), ("B", "q", 0.9, 1.4)]
    for seed in (0, 1):
        proposal = settled_ask_after_a_crawl(first, seed)
        assert "settled" in proposal.meta
        assert (proposal.params["catalyst"], proposal.params["ligand"]) == ("C", "p")
        assert proposal.params["x0"] == pytest.approx(0.8)


def test_a_settled_campaign_whose_neighbours_have_all_run_changes_two_options():
    """Every combination one option away from A / p (B / p, C / p, A / q) has run, B / q and C / q have not: the
    settled ask runs one of those two at the best result's conditions."""
    first = [("B", "p", 0.3, 0.8), ("C", "p", 0.6, 1.2), ("A", "q", 0.5, 0.9), ("B", "p", 0.8, 0.7),
             ("C", "p", 0.2, 1.3), ("A", "q", 0.9, 0.8), ("B", "p", 0.5, 0.75), ("A", "q", 0.1, 1.0)]
    for seed in (0, 1):
        proposal = settled_ask_after_a_crawl(first, seed)
        assert "settled" in proposal.meta
        assert (proposal.params["catalyst"], proposal.params["ligand"]) in {("B", "q"), ("C", "q")}
        assert proposal.params["x0"] == pytest.approx(0.8)
