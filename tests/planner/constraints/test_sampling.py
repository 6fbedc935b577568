"""Start points inside tiny and disconnected feasible sets: hit-and-run from known feasible points."""

import numpy as np
import pytest

from gryffin_ros.planner import KnownConstraints, NoFeasiblePointError, Planner, SearchSpace
from gryffin_ros.planner.constraints.sampling import hit_and_run, spread_seeds


def unit_space(d):
    return SearchSpace.from_config([{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(d)])


def ball(d, centre, radius):
    return " + ".join(f"(x{i} - {centre}) ** 2" for i in range(d)) + f" <= {radius * radius!r}"


def test_hit_and_run_stays_feasible_and_fills_an_annulus():
    space = unit_space(2)
    constraints = KnownConstraints.build(space, ["0.04 <= (x0 - 0.5) ** 2 + (x1 - 0.5) ** 2 <= 0.09"])
    rng = np.random.default_rng(0)
    X = hit_and_run(constraints, rng, np.array([[0.75, 0.5]]), 600, steps=600)
    assert len(X) == 600 and constraints.feasible(X).all()
    angles = np.arctan2(X[:, 1] - 0.5, X[:, 0] - 0.5)
    counts = np.histogram(angles, bins=4, range=(-np.pi, np.pi))[0]
    assert counts.min() > 0.5 * counts.mean()  # one seed, the whole ring visited about evenly
    assert abs(np.mean(X, axis=0) - 0.5).max() < 0.05


def test_hit_and_run_moves_finite_dims_only_to_feasible_options():
    space = SearchSpace.from_config([{"name": "x0", "type": "continuous", "low": 0, "high": 1},
                                     {"name": "c", "type": "categorical", "options": ["a", "b", "c"]}])
    constraints = KnownConstraints.build(space, ["c != 'b' and x0 < 0.2"])
    X = hit_and_run(constraints, np.random.default_rng(1), np.array([[0.1, 0.0]]), 200)
    assert constraints.feasible(X).all() and set(X[:, 1]) == {0.0, 2.0}


def test_spread_seeds_keeps_a_point_of_every_separate_cluster():
    rng = np.random.default_rng(2)
    big = rng.normal(0.3, 0.05, (2000, 2))
    small = np.array([[0.9, 0.9], [0.901, 0.899]])
    seeds = spread_seeds(unit_space(2), np.concatenate([big, small]), 8, rng)
    assert len(seeds) == 8 and (np.linalg.norm(seeds - 0.9, axis=1) < 0.01).any()


def test_feasible_proposals_in_a_4d_ball_of_one_ten_thousandth_of_the_domain():
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(4)],
              "objectives": [{"name": "y", "goal": "min"}], "constraints": [ball(4, 0.3, 0.07)]}
    planner = Planner(config, seed=0)
    assert 2e-5 < planner.feasible_fraction.value < 1e-3
    for _ in range(4):
        (proposal,) = planner.ask()
        x = np.array([proposal.params[f"x{i}"] for i in range(4)])
        assert np.linalg.norm(x - 0.3) <= 0.07
        planner.tell({**proposal.params, "y": float(((x - 0.32) ** 2).sum()), "experiment_id": proposal.experiment_id})


def test_a_one_in_a_million_region_gives_a_clear_error_or_proposals_from_a_known_experiment():
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(6)],
              "objectives": [{"name": "y", "goal": "min"}], "constraints": [ball(6, 0.3, 0.0762)]}  # ~1e-6
    planner = Planner(config, seed=0)
    with pytest.raises(NoFeasiblePointError, match="uniform samples"):
        planner.ask()
    planner.tell({**{f"x{i}": 0.3 for i in range(6)}, "y": 1.0})  # one experiment the chemist knows is feasible
    assert planner.feasible_fraction.method == "upper_bound"
    proposals = planner.ask(3)
    for proposal in proposals:
        x = np.array([proposal.params[f"x{i}"] for i in range(6)])
        assert np.linalg.norm(x - 0.3) <= 0.0762
    assert len({tuple(p.params.values()) for p in proposals}) == 3


def test_disconnected_regions_of_volume_ratio_1_to_1000_both_get_visited():
    """The optimum sits in the small disc (area 2.8e-4, next to a disc of area 0.28)."""
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(2)],
              "objectives": [{"name": "y", "goal": "min"}],
              "constraints": ["(x0 - 0.3) ** 2 + (x1 - 0.3) ** 2 <= 0.09 or "
                              "(x0 - 0.85) ** 2 + (x1 - 0.85) ** 2 <= 0.0095 ** 2"]}
    for seed in range(3):
        planner = Planner(config, seed=seed)
        visits = 0
        for _ in range(15):
            (proposal,) = planner.ask()
            x = np.array([proposal.params["x0"], proposal.params["x1"]])
            small = np.linalg.norm(x - 0.85) <= 0.0095
            assert small or np.linalg.norm(x - 0.3) <= 0.3
            visits += small
            planner.tell({**proposal.params, "y": float(np.linalg.norm(x - 0.85)),
                          "experiment_id": proposal.experiment_id})
        assert visits >= 1  # uniform sampling alone would need ~1000 draws per visit
        assert planner.best().objectives["y"] <= 0.0095


def test_start_points_never_miss_a_small_region_that_was_found():
    """Uniform start points hit a 1:1000 region about once in three asks; the hit-and-run share puts start points
    in it at every ask, while the big region still gets the vast majority."""
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(2)],
              "objectives": [{"name": "y", "goal": "min"}],
              "constraints": ["(x0 - 0.3) ** 2 + (x1 - 0.3) ** 2 <= 0.09 or "
                              "(x0 - 0.85) ** 2 + (x1 - 0.85) ** 2 <= 0.0095 ** 2"]}
    planner = Planner(config, seed=4)
    rows = [{"x0": 0.3, "x1": 0.3}, {"x0": 0.1, "x1": 0.4}, {"x0": 0.45, "x1": 0.2}]
    planner.tell([{**row, "y": 1.0} for row in rows])
    X = planner.observed_points()
    small_share = []
    for k in range(20):
        start, _ = planner.start_points(np.random.default_rng(k), X[0], X)
        small = np.linalg.norm(start - 0.85, axis=1) <= 0.0095
        assert planner.constraints.feasible(start).all()
        small_share.append(small.mean())
    assert min(small_share) > 0  # in every ask
    assert max(small_share) < 0.05  # and far below the big region's share
