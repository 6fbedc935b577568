"""The GP classifier of feasibility (general.feas_model = gp): what it learns from failures, its fallback to the
kernel-density model, and the known constraints it must never loosen."""

import numpy as np
import pytest

from gryffin_ros.planner import Planner
from gryffin_ros.planner.surrogates import gp_classifier
from gryffin_ros.planner.surrogates.gp_classifier import ClassifierFitError, GPClassifier

SQUARE = {"parameters": [{"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                         {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}],
          "objectives": [{"name": "y", "goal": "min"}]}
GRID = {"parameters": [{"name": n, "type": "categorical", "options": [f"o{i}" for i in range(6)]} for n in ("a", "b")],
        "objectives": [{"name": "y", "goal": "min"}]}


def corner_data(rng):
    """40 points of the unit square; those with x0 > 0.6 and x1 > 0.6 failed."""
    X = rng.random((40, 2))
    return X, (X[:, 0] > 0.6) & (X[:, 1] > 0.6)


def test_probability_is_low_among_clustered_failures_and_high_among_successes():
    X, failed = corner_data(np.random.default_rng(0))
    classifier = GPClassifier(Planner(SQUARE, seed=0).space, X, failed, seed=0)
    p_failing, p_ok = classifier.probability(np.array([[0.85, 0.85], [0.2, 0.2]]))
    assert p_failing < 0.5 < 0.8 < p_ok
    p = classifier.probability(np.random.default_rng(1).random((100, 2)))
    assert ((0.0 <= p) & (p <= 1.0)).all()


def test_categories_without_descriptors_are_one_hot_and_a_failing_option_is_learned():
    planner = Planner(GRID, seed=0)
    X = np.array([[i, j] for i in range(6) for j in range(6)], dtype=float)
    classifier = GPClassifier(planner.space, X, X[:, 0] == 2, seed=0)
    assert classifier.inputs(X).shape == (36, 12)
    p_failing, p_ok = classifier.probability(np.array([[2.0, 3.0], [4.0, 3.0]]))
    assert p_failing < p_ok


def square_campaign(general, constraint=None, n=4, seed=3):
    """Proposals of n asks after three failures (x0 > 0.6, x1 < 0.4 fails) and two successes."""
    config = {**SQUARE, "general": {"feas_model": "gp", **general}}
    if constraint:
        config["constraints"] = [constraint]
    planner = Planner(config, seed=seed)

    def y(x0, x1):
        return None if x0 > 0.6 and x1 < 0.4 else (x0 - 0.3) ** 2 + (x1 - 0.6) ** 2
    planner.tell([{"x0": x0, "x1": x1, "y": y(x0, x1)}
                  for x0, x1 in ((0.7, 0.1), (0.8, 0.3), (0.9, 0.2), (0.2, 0.5), (0.4, 0.7))])
    proposals = []
    for _ in range(n):
        (proposal,) = planner.ask()
        proposals.append(proposal)
        planner.tell({**proposal.params, "y": y(proposal.params["x0"], proposal.params["x1"]),
                      "experiment_id": proposal.experiment_id})
    return proposals


@pytest.mark.parametrize("surrogate, approach", [("kde", "fwa"), ("gp", "fwa"), ("kde", "fia"), ("gp", "fca")])
def test_known_constraints_hold_with_the_gp_classifier(surrogate, approach):
    proposals = square_campaign({"surrogate": surrogate, "feas_approach": approach}, "x0 + x1 <= 1.2")
    assert all(p.params["x0"] + p.params["x1"] <= 1.2 for p in proposals)


def test_a_classifier_that_cannot_be_fitted_falls_back_to_the_kernel_estimate_and_says_so(monkeypatch):
    def broken(self, Z, y):
        raise ClassifierFitError("the feasibility classifier could not be fitted: not positive definite")
    monkeypatch.setattr(gp_classifier.GPClassifier, "_fit", broken)
    last = square_campaign({"surrogate": "kde"}, n=1)[-1]
    assert last.meta["feas_model"] == "kde"
    assert "could not be fitted" in last.meta["feas_model_reason"]


def test_a_fitted_classifier_leaves_no_fallback_note():
    last = square_campaign({"surrogate": "kde"}, n=1)[-1]
    assert "feas_model_reason" not in last.meta
