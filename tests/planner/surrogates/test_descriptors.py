"""Dynamic descriptors: the learned transform finds the descriptor that explains the objective."""

import numpy as np
import pytest

from gryffin_ros.planner import Planner
from gryffin_ros.planner.surrogates.descriptors import learn_descriptors, learn_many

OPTIONS = [f"m{i}" for i in range(10)]
RNG = np.random.default_rng(0)
# descriptor 0 drives the objective, descriptor 1 is noise
DESCRIPTORS = {o: [float(i), float(RNG.uniform(0, 10))] for i, o in enumerate(OPTIONS)}


def objective(option: str) -> float:
    return (DESCRIPTORS[option][0] - 7.0) ** 2


def test_relevant_descriptor_is_kept_and_ranked_first():
    table = np.array([DESCRIPTORS[o] for o in OPTIONS])
    table = (table - table.min(0)) / np.ptp(table, axis=0)
    options = np.array([0, 1, 2, 3, 4, 5, 6, 8, 9, 3, 5])
    target = np.array([objective(OPTIONS[i]) for i in options])
    learned = learn_descriptors(table, options, target)
    assert learned is not None
    assert learned.relevance[0] > 0.6 > learned.relevance[1]
    assert np.abs(learned.correlations).max() > 1 / np.sqrt(len(options) - 2)
    assert learned.table.shape == (10, learned.kept.sum())
    assert learned.table.min() == 0.0 and learned.table.max() == 1.0


def test_too_little_or_constant_data_learns_nothing():
    table = np.array([DESCRIPTORS[o] for o in OPTIONS]) / 10.0
    assert learn_descriptors(table, np.array([0, 1, 2]), np.array([1.0, 2.0, 3.0])) is None
    assert learn_descriptors(table, np.array([0, 1, 2, 3, 4]), np.ones(5)) is None


def test_descriptor_constant_over_the_observed_options_is_left_out_not_fatal():
    # column 1 is the same for every observed option (its correlation would be 0/0); the others still learn
    table = np.array([[0.0, 1.0, 0.0], [1.0, 1.0, 0.5], [0.5, 1.0, 1.0], [0.2, 0.0, 0.3]])
    options = np.array([0, 1, 2, 0, 1, 2])
    learned = learn_descriptors(table, options, np.array([1.0, 2.0, 3.0, 1.5, 2.5, 2.0]))
    assert learned is not None and np.isfinite(learned.table).all()
    assert not learned.kept[1] and learned.correlations[1] == 0.0 and learned.relevance[1] == 0.0
    # relevance is sensitivity / sensitivity.sum(): each quotient is rounded (half an ulp), so the shares sum to 1
    # within a few ulp (about 1e-16), not exactly, and which way depends on the learned values of this CPU
    assert learned.kept[[0, 2]].any() and learned.relevance.sum() == pytest.approx(1.0, abs=1e-12)


def test_batched_learning_equals_learning_each_parameter_alone():
    rng = np.random.default_rng(1)
    target = rng.uniform(size=30)
    problems = [(rng.uniform(size=(k, m)), rng.integers(0, k, 30)) for k, m in [(2, 4), (8, 7), (11, 7), (5, 3)]]
    together = learn_many(problems, target)
    assert sum(r is not None for r in together) >= 3
    for (table, options), result in zip(problems, together):
        alone = learn_descriptors(table, options, target)
        assert (result is None) == (alone is None)
        if result is None:
            continue
        # |correlation| - 1/sqrt(N - 2) is at least 4.5e-5 here, far above the differences below: kept cannot flip
        np.testing.assert_array_equal(result.kept, alone.kept)
        if np.unique(options).size > 2:
            # Batched and alone are the same arithmetic on differently shaped (zero-padded) tensors, so they differ
            # by rounding, which 300 Adam steps amplify: one-ulp changes of the inputs move these results by up to
            # 3e-11 (measured). 1e-6 leaves five orders of magnitude for other CPUs, BLAS builds and thread counts,
            # while a real coupling of the problems (one problem's weight penalty off by 10 %, as a penalty
            # normalized over the batch would be) moves them by 7e-4 or more.
            np.testing.assert_allclose(result.table, alone.table, atol=1e-6)
            np.testing.assert_allclose(result.correlations, alone.correlations, atol=1e-6)
            np.testing.assert_allclose(result.relevance, alone.relevance, atol=1e-6)
        else:
            # Two observed options: every generated column is two-valued, so every |correlation| (among the columns,
            # and with the target) is the same for any weights, the loss is flat in them but for the small penalty,
            # and Adam follows rounding noise: one-ulp changes of the inputs flip the table's columns and move the
            # relevance by 0.2. What is determined is |correlation| with the target (that of the option indicator),
            # equal up to the rounding of 30-term sums (1e-16).
            np.testing.assert_allclose(np.abs(result.correlations), np.abs(alone.correlations), atol=1e-12)


def test_planner_with_dynamic_descriptors_reports_relevance_and_finds_the_optimum():
    config = {"parameters": [{"name": "mol", "type": "categorical", "options": OPTIONS, "descriptors": DESCRIPTORS}],
              "objectives": [{"name": "y", "goal": "min"}], "general": {"auto_desc_gen": True}}
    planner = Planner(config, seed=3)
    for _ in range(8):
        (proposal,) = planner.ask()
        planner.tell({**proposal.params, "y": objective(proposal.params["mol"]),
                      "experiment_id": proposal.experiment_id})
    summary = planner.descriptor_summary()
    relevance = summary["mol"]["objective"]["relevance"]
    assert relevance[0] > relevance[1]
    assert planner.best().params == {"mol": "m7"}
