"""The dashboard's data, from a real store: what the page shows, without a browser."""

import json
import sys

import numpy as np
import pytest

from gryffin_ros.campaign import Campaign
from gryffin_ros.dashboard.view import GRID, CampaignView
from gryffin_ros.planner.config import load_config
from gryffin_ros.planner.merit import best_so_far

from .conftest import CONFIG, add_one


def test_the_view_holds_every_experiment_pending_and_rejected_one(campaign):
    view = CampaignView(campaign.store.path)
    data = view.campaign()
    json.dumps(data, allow_nan=False)  # valid JSON: no NaN or infinity anywhere
    assert [e["seq"] for e in data["experiments"]] == [1, 2, 3, 4, 5]
    assert [e["failed"] for e in data["experiments"]] == [False, False, True, False, False]
    assert data["experiments"][2]["objectives"] == {"y": None, "cost": None}
    assert len(data["pending"]) == 1 and data["pending"][0]["experiment_id"] == campaign.pending[0].experiment_id
    assert [r["experiment_id"] for r in data["rejected"]] == ["made-up"]
    assert {p["name"]: p["units"] for p in data["parameters"]} == {"x": "mL", "solvent": ""}
    assert data["tolerances"] == {"y": 0.5, "cost": None}
    assert data["hierarchy"] == "y >= 0.5, then cost as low as possible"
    expected = best_so_far(load_config(CONFIG), campaign.store.observations())
    assert data["best"]["y"] == [None if b is None else b.objectives["y"] for b in expected]
    # the conditions of the best experiment now head the page
    assert data["best_experiment"]["experiment_id"] == expected[-1].experiment_id
    assert data["best_experiment"]["params"] == expected[-1].params
    view.close()


def test_the_view_follows_the_store_and_recomputes_only_when_it_changed(campaign):
    view = CampaignView(campaign.store.path)
    first = view.campaign()
    assert view.campaign() is first  # nothing changed: the same data, not computed again
    add_one(campaign)
    second = view.campaign()
    assert len(second["experiments"]) == 6 and second["version"] != first["version"]
    view.close()


def test_the_feasible_region_comes_from_the_planners_constraints(campaign):
    view = CampaignView(campaign.store.path)
    region = view.feasible("x", "solvent")
    assert region["y"]["values"] == ["THF", "DMF"] and len(region["x"]["values"]) == GRID
    share = np.array(region["share"])  # rows: solvent; columns: x
    x = np.array(region["x"]["values"])
    # the constraint involves only these two parameters: each cell is wholly feasible or not
    np.testing.assert_array_equal(share[0], (x < 4).astype(float))
    np.testing.assert_array_equal(share[1], (x < 8).astype(float))
    view.close()


def test_a_config_whose_constraints_cannot_be_loaded_still_shows_the_campaign(tmp_path):
    from gryffin_ros.storage import CampaignStore
    raw = {**CONFIG, "constraints": [{"plugin": "lookup", "options": {"file": "feasible.csv"}}]}
    CampaignStore(tmp_path / "c.sqlite", raw, "h").close()
    view = CampaignView(tmp_path / "c.sqlite", config_dir=tmp_path / "elsewhere")
    data = view.campaign()
    assert data["experiments"] == [] and "feasible.csv" in data["constraint_error"]
    view.close()


def test_shares_by_category_are_the_same_where_the_constraint_ignores_the_category(tmp_path):
    """x + y < 1.2 does not involve the solvent: along x, each solvent's row is the same estimate (every cell judged
    at the same completions), and near the truth P(y < 1.2 - x) for y uniform on [0, 1]."""
    from gryffin_ros.storage import CampaignStore
    raw = {"name": "shares", "objectives": [{"name": "z", "goal": "max"}], "constraints": ["x + y < 1.2"],
           "parameters": [{"name": "x", "type": "continuous", "low": 0.0, "high": 1.0},
                          {"name": "y", "type": "continuous", "low": 0.0, "high": 1.0},
                          {"name": "solvent", "type": "categorical", "options": ["water", "ethanol", "dmso"]}]}
    CampaignStore(tmp_path / "c.sqlite", raw, "h").close()
    view = CampaignView(tmp_path / "c.sqlite")
    region = view.feasible("x", "solvent")
    share = np.array(region["share"])  # rows: solvent; columns: x
    assert (share == share[0]).all()
    x = np.array(region["x"]["values"])
    truth = np.clip(1.2 - x, 0.0, 1.0)
    completions = 16 * GRID * GRID // share.size
    # a share of n independent draws: 4 standard errors of the worst case p = 0.5 (a cell off by chance: 6e-5)
    assert np.abs(share[0] - truth).max() < 4 * np.sqrt(0.25 / completions)
    view.close()


def test_the_view_of_a_molecule_campaign_needs_no_rdkit_for_what_was_stored(tmp_path, monkeypatch):
    pytest.importorskip("rdkit")
    config = {"name": "m", "parameters": [{"name": "solvent", "type": "categorical",
                                           "options": {"toluene": "Cc1ccccc1", "DMF": "CN(C)C=O"}}],
              "constraints": ["weight(solvent) < 80"]}
    with Campaign(config, tmp_path / "m.sqlite", seed=0) as campaign:
        campaign.propose(1)
    monkeypatch.setitem(sys.modules, "rdkit", None)
    view = CampaignView(tmp_path / "m.sqlite")
    assert view.constraint_error is None  # the constraint was loaded from the stored values
    assert view.campaign()["parameters"][0]["smiles"] == {"toluene": "Cc1ccccc1", "DMF": "CN(C)C=O"}
    assert view.campaign()["pending"][0]["params"] == {"solvent": "DMF"}
    view.close()
