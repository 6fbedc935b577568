"""Dynamic descriptors: the learned transform finds the descriptor that explains the objective."""

import numpy as np

from gryffin_ros.planner import Planner
from gryffin_ros.planner.descriptors import learn_descriptors

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
