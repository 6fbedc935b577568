"""Failed experiments as unknown constraints: the classifier, its combination with the acquisition, and a campaign
that learns to avoid a region it was never told about."""

import numpy as np
import pytest
import torch

from benchmarks.failing_region import deep
from gryffin_ros.planner import Planner, load_config
from gryffin_ros.planner.acquisition import feasibility
from gryffin_ros.planner.acquisition.feasibility import FeasibilityModel, combine
from tests.conftest import branin

SQUARE = {"parameters": [{"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                         {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}],
          "objectives": [{"name": "y", "goal": "min"}]}


def model(X, failed):
    planner = Planner(SQUARE, seed=0)
    return FeasibilityModel(planner.space, np.asarray(X, float), np.asarray(failed), 1.0,
                            torch.Generator().manual_seed(0))


def test_probability_is_low_near_failures_high_near_successes_and_the_prior_far_away():
    rng = np.random.default_rng(0)
    bad = rng.uniform(0.0, 0.2, (8, 2))
    good = rng.uniform(0.8, 1.0, (8, 2))
    m = model(np.concatenate([bad, good]), [True] * 8 + [False] * 8)
    p_bad, p_good = m.probability(np.array([[0.1, 0.1]]))[0], m.probability(good[:1])[0]
    p_far = m.probability(np.array([[0.1, 0.9]]))[0]
    assert p_bad < 0.2 and p_good > 0.8
    assert m.prior == pytest.approx(9 / 18)
    assert p_far == pytest.approx(m.prior, abs=0.1)
    assert 0.0 <= m.probability(rng.random((200, 2))).min() <= m.probability(rng.random((200, 2))).max() <= 1.0


def coupling(bases: int = 4) -> Planner:
    """A ligand, a base and a solvent (categorical) and three conditions, as in a coupling screen."""
    return Planner({"parameters": [{"name": "ligand", "type": "categorical", "options": [f"l{i}" for i in range(5)]},
                                   {"name": "base", "type": "categorical", "options": [f"b{i}" for i in range(bases)]},
                                   {"name": "solvent", "type": "categorical", "options": [f"s{i}" for i in range(5)]}]
                    + [{"name": f"c{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(3)],
                    "objectives": [{"name": "y", "goal": "min"}]}, seed=0)


def base_failures(seed: int, bases: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Internal points and failure labels: bases 0-2 succeed (20 random points, and 3 at the conditions QUERY[0] holds);
    base 3 failed in each of its 4 runs, at random other points."""
    rng = np.random.default_rng(seed)

    def draw(n, base):
        return np.c_[rng.integers(0, 5, n), rng.integers(0, 3, n) if base is None else np.full(n, base),
                     rng.integers(0, 5, n), rng.random((n, 3))]
    ok = np.concatenate([draw(20, None), [[2, b, 1, 0.5, 0.0, 0.0] for b in range(3)]])
    return np.concatenate([ok, draw(4, 3)]), np.array([False] * len(ok) + [True] * 4)


QUERY = np.array([[2, 0, 1, 0.5, 0.0, 0.0], [2, 3, 1, 0.5, 0.0, 0.0]])  # base 0, then base 3, at the same conditions


@pytest.mark.parametrize("seed", [0, 1])
def test_an_option_that_failed_in_every_run_is_unlikely_wherever_it_is_set(seed, monkeypatch):
    planner = coupling()
    X, failed = base_failures(seed)
    p = FeasibilityModel(planner.space, X, failed, 1.0, torch.Generator().manual_seed(seed)).probability(QUERY)
    monkeypatch.setattr(feasibility, "OPTION_PRIOR_WEIGHT", 0.0)
    kernels = FeasibilityModel(planner.space, X, failed, 1.0, torch.Generator().manual_seed(seed)).probability(QUERY)
    # what the rule is for: the kernels alone, local in all six coordinates at once, let the successes of the other
    # bases at these conditions vouch for base 3
    assert kernels[1] > 0.5
    # base 3's rate: (0 successes + prior) / (4 runs + 1 pseudo-run), against the prior: a factor 1/5
    assert p[1] == pytest.approx(kernels[1] / 5) and p[1] < 0.25
    assert p[0] == kernels[0] > 0.8  # a base that never failed: unchanged


def test_an_option_that_failed_once_among_many_successes_keeps_most_of_its_probability():
    planner = coupling()
    X, failed = base_failures(0)
    failed[np.flatnonzero(X[:, 1] == 0)[0]] = True  # one run of base 0 failed too
    factors = FeasibilityModel(planner.space, X, failed, 1.0, torch.Generator().manual_seed(0)).option_factors
    assert factors[1][0] > 0.8 and factors[1][1] == factors[1][2] == 1.0 and factors[1][3] < 0.25
    # the ligand and the solvent have factors too: their options that ran with base 3 share its failures (a marginal
    # rate cannot tell which parameter failed), milder than base 3's own
    assert set(factors) == {0, 1, 2} and min(factors[0].min(), factors[2].min()) > factors[1][3]


def test_a_campaign_s_proposals_name_the_option_that_keeps_failing():
    planner = coupling()
    X, failed = base_failures(0)
    names = planner.space.names
    rows = [{**{n: planner.space.parameters[d].options[int(x[d])] for d, n in enumerate(names[:3])},
             **{n: float(x[d]) for d, n in enumerate(names) if d >= 3},
             "y": None if bad else float(np.sum((x[3:] - 0.4) ** 2))} for x, bad in zip(X, failed)]
    planner.tell(rows)
    (proposal,) = planner.ask()
    assert proposal.meta["failing_options"] == "base=b3 (0 of 4 succeeded)"


def test_a_parameter_with_many_options_has_no_option_factor():
    bases = feasibility.OPTION_MAX_OPTIONS + 1
    planner = coupling(bases)
    X, failed = base_failures(0, bases)
    assert 1 not in FeasibilityModel(planner.space, X, failed, 1.0, torch.Generator().manual_seed(0)).option_factors


def test_combinations_follow_their_definitions():
    alpha = np.array([0.0, 0.5, 1.0])
    p = np.array([0.2, 0.9, 1.0])
    assert combine(alpha, p, "fwa", 1.0, 0.5) == pytest.approx([-0.2, -0.45, 0.0])
    assert combine(alpha, p, "fwt", 1.0, 0.5) == pytest.approx([-0.4, -0.5, 0.0])  # P / 0.5, at most 1
    w = 0.5 ** 2.0
    assert combine(alpha, p, "fia", 2.0, 0.5) == pytest.approx(w * (1 - p) + (1 - w) * np.array([0, 0.5, 1]))
    assert combine(alpha, p, "fca", 0.5, 0.5).tolist() == [np.inf, 0.5, 1.0]
    # nothing passes 0.99: the threshold is relaxed until at least 10 % of candidates pass
    relaxed = combine(alpha, p * 0.5, "fca", 0.99, 0.5)
    assert np.isfinite(relaxed).sum() >= 1


def test_with_every_experiment_failed_the_next_proposals_go_away_from_the_failures():
    planner = Planner(SQUARE, seed=1)
    failures = [{"x0": 0.1 + 0.02 * i, "x1": 0.1 + 0.01 * i, "y": None} for i in range(6)]
    planner.tell(failures)
    for proposal in planner.ask(2):
        x = np.array([proposal.params["x0"], proposal.params["x1"]])
        assert min(np.hypot(*(x - [f["x0"], f["x1"]])) for f in failures) > 0.25


def test_the_default_lets_a_likely_feasible_best_candidate_win_that_fwa_gives_away():
    """The best acquisition at P = 0.6 (beside a few failures) against a slightly worse one at P = 1: fwa's product
    prefers the worse one, fwt (the default) counts P from 0.5 up as feasible and keeps the best; a candidate at
    P = 0.2 is still weighed down, not cut off as fca would."""
    alpha, p = np.array([0.0, 0.2, 1.0, 0.0]), np.array([0.6, 1.0, 1.0, 0.2])
    assert load_config(SQUARE).general.feas_approach == "fwt"
    assert int(np.argmin(combine(alpha, p, "fwa", 1.0, 0.3))) == 1
    scores = combine(alpha, p, "fwt", 1.0, 0.3)
    assert int(np.argmin(scores)) == 0 and np.isfinite(scores[3]) and scores[3] < scores[2]


@pytest.mark.parametrize("approach", ["fwt", "fwa", "fia", "fca"])
def test_every_feasibility_approach_proposes_feasible_points(approach):
    config = {**SQUARE, "constraints": ["x0 + x1 <= 1.5"], "general": {"feas_approach": approach}}
    planner = Planner(config, seed=2)
    rng = np.random.default_rng(2)
    for _ in range(12):
        (proposal,) = planner.ask()
        assert proposal.params["x0"] + proposal.params["x1"] <= 1.5
        y = None if rng.random() < 0.4 else float(proposal.params["x0"])
        planner.tell({**proposal.params, "y": y, "experiment_id": proposal.experiment_id})


def share_inside(seed, fails, objective, counted_from=0, experiments=60, counts=None):
    """Run a campaign of `experiments` on the unit square where `fails(x0, x1)` experiments fail (reported as None,
    the planner not told) and the others give `objective(x0, x1)`; the share of experiments `counted_from` + 1 ..
    `experiments` that went inside the failing region (or, given `counts(x0, x1)`, that it holds)."""
    planner = Planner(SQUARE, seed=seed)
    inside = 0
    for experiment in range(experiments):
        (proposal,) = planner.ask()
        x0, x1 = proposal.params["x0"], proposal.params["x1"]
        failed = fails(x0, x1)
        inside += (failed if counts is None else counts(x0, x1)) and experiment >= counted_from
        planner.tell({**proposal.params, "y": None if failed else float(objective(x0, x1)),
                      "experiment_id": proposal.experiment_id})
    return inside / (experiments - counted_from)


@pytest.mark.slow
def test_a_region_that_always_fails_is_learned_and_avoided():
    """x0 > 0.5 and x1 > 0.5 fails (a quarter of the domain); the planner is not told. Over 60 experiments it must
    propose there far less often than the region's area (uniform sampling: 25 %; measured: about 5 %)."""
    def fails(x0, x1):
        return x0 > 0.5 and x1 > 0.5

    def objective(x0, x1):
        return (x0 - 0.25) ** 2 + (x1 - 0.3) ** 2 + 0.05 * np.sin(20 * x0)
    assert np.mean([share_inside(seed, fails, objective) for seed in (0, 1)]) < 0.125


@pytest.mark.slow
def test_a_failing_quarter_that_holds_the_trend_s_best_is_left_once_learned():
    """Branin on the unit square with the quarter x0 > 0.5, x1 < 0.5 failing (two of its three minima inside; the
    planner is not told). The GP, fitted to the successes alone, keeps expecting large improvements in there; the
    default must still send fewer of experiments 31-60 inside than uniform sampling would (25 %). Measured on these
    seeds: 1, 2 and 1 of 30 (with the wide estimate's prior worth one observation, not WIDE_PRIOR_WEIGHT: 1, 2 and 0;
    before fwt's compressed tail of -log EI, EI_TAIL_SLOPE: 4, 5 and 0; before failures were
    believed at the incumbent and fwt's weight was raised to FEASIBILITY_POWER: 26, 21 and 10)."""
    def fails(x0, x1):
        return x0 > 0.5 and x1 < 0.5
    assert np.mean([share_inside(seed, fails, branin, counted_from=30) for seed in (0, 1, 2)]) < 0.25


@pytest.mark.slow
def test_a_failing_quarter_that_holds_the_unconstrained_optimum_is_probed_at_its_edge_not_deep_inside():
    """(x0 - 0.65)^2 + (x1 - 0.7)^2 with the quarter x0 > 0.5, x1 > 0.5 failing: the best feasible points lie on the
    quarter's edge, where about half of any probes fail, and nothing is gained deep inside. Of experiments 31-60, those
    deep inside (benchmarks.failing_region.deep: 0.03 from the edge or more; uniform sampling: about 22 %) must stay
    few. Measured on these seeds: 1 and 0 of 30 (before fwt's compressed tail of -log EI, EI_TAIL_SLOPE: 17 and 19,
    the GP's negligible EI there, among failures believed at the incumbent, outweighing P(feasible) ~ 0.1)."""
    def fails(x0, x1):
        return x0 > 0.5 and x1 > 0.5

    def objective(x0, x1):
        return (x0 - 0.65) ** 2 + (x1 - 0.7) ** 2

    def deep_inside(x0, x1):
        return deep(fails, x0, x1)
    assert np.mean([share_inside(seed, fails, objective, counted_from=30, counts=deep_inside)
                    for seed in (0, 1)]) < 0.1
