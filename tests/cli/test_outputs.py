"""What a campaign leaves behind: the plot's hierarchy and tolerance lines, units from the config."""

import numpy as np
import pytest

from gryffin_ros.cli.outputs import plot
from gryffin_ros.planner import ConfigError, Observation, load_config
from gryffin_ros.planner.chimera import hierarchy, tolerance_line
from gryffin_ros.storage import CampaignStore

FLOW = {"name": "flow", "parameters": [{"name": "F_C", "type": "continuous", "low": 0, "high": 200, "units": "uL/min"},
                                       {"name": "T", "type": "continuous", "low": 100, "high": 150}],
        "objectives": [{"name": "X1_X2", "goal": "max", "tolerance": 0.9, "absolute": True},
                       {"name": "cost", "goal": "min", "units": "$/min"}]}


def test_units_label_axes_and_columns_and_must_be_text():
    config = load_config(FLOW)
    assert (config.label("F_C"), config.label("T"), config.label("cost")) == ("F_C (uL/min)", "T", "cost ($/min)")
    with pytest.raises(ConfigError, match="'units' must be a string"):
        load_config({**FLOW, "objectives": [{"name": "cost", "goal": "min", "units": 5}]})


def test_the_chimera_hierarchy_in_words():
    assert hierarchy(load_config(FLOW)) == "X1_X2 >= 0.9, then cost as low as possible"
    relative = {**FLOW, "objectives": [{"name": "y", "goal": "min", "tolerance": 0.1}, {"name": "z", "goal": "max"}]}
    assert hierarchy(load_config(relative)) == "y within 10% of its best, then z as high as possible"


def test_tolerance_lines_absolute_and_relative_to_the_observed_range():
    absolute, second = load_config(FLOW).objectives
    assert tolerance_line(absolute, np.array([0.2, 0.5])) == 0.9
    assert tolerance_line(second, np.array([1.0, 2.0])) is None  # no tolerance
    relative = load_config({**FLOW, "objectives": [{"name": "y", "goal": "max", "tolerance": 0.2},
                                                   {"name": "z", "goal": "min"}]}).objectives[0]
    assert tolerance_line(relative, np.array([0.0, np.nan, 10.0])) == pytest.approx(8.0)


def test_the_plot_draws_a_campaign_with_a_failed_experiment(tmp_path):
    config = load_config(FLOW)
    store = CampaignStore(tmp_path / "c.sqlite", config.raw, config.hash)
    store.add_observation(Observation({"F_C": 10.0, "T": 120.0}, {"X1_X2": 0.95, "cost": 0.02}, "a"))
    store.add_observation(Observation({"F_C": 20.0, "T": 130.0}, {"X1_X2": None, "cost": None}, "b"))
    store.add_observation(Observation({"F_C": 5.0, "T": 110.0}, {"X1_X2": 0.91, "cost": 0.01}, "c"))
    plot(store, config, tmp_path / "p.png")
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
