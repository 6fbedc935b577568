"""A short campaign written to a real store, for the dashboard to read."""

import pytest

from gryffin_ros.campaign import Campaign, Rejected

CONFIG = {
    "name": "board_test",
    "parameters": [{"name": "x", "type": "continuous", "low": 0.0, "high": 10.0, "units": "mL"},
                   {"name": "solvent", "type": "categorical", "options": ["THF", "DMF"]}],
    "objectives": [{"name": "y", "goal": "max", "tolerance": 0.5, "absolute": True, "units": "%"},
                   {"name": "cost", "goal": "min", "units": "$"}],
    "constraints": ["x < 4 if solvent == 'THF' else x < 8"],
}


def measure(params):
    return {"y": params["x"] / 10.0, "cost": 1.0 + params["x"]}


@pytest.fixture
def campaign(tmp_path):
    """A campaign of 5 experiments (one failed), one pending and one rejected observation; the test holds it."""
    campaign = Campaign(CONFIG, tmp_path / "campaign.sqlite", seed=0)
    for k in range(5):
        (proposal,) = campaign.propose(1)
        objectives = {"y": None, "cost": None} if k == 2 else measure(proposal.params)
        campaign.observe({"experiment_id": proposal.experiment_id, "params": proposal.params,
                          "objectives": objectives})
    campaign.propose(1)
    with pytest.raises(Rejected):
        campaign.observe({"experiment_id": "made-up", "params": {"x": 1.0, "solvent": "THF"},
                          "objectives": {"y": 0.1, "cost": 2.0}})
    yield campaign
    campaign.close()


def add_one(campaign):
    """One more experiment, as a running campaign would add it."""
    (proposal,) = campaign.pending or campaign.propose(1)
    campaign.observe({"experiment_id": proposal.experiment_id, "params": proposal.params,
                      "objectives": measure(proposal.params)})
