"""The SQLite campaign store: commit before acknowledge, resume, refuse another config, export."""

import csv
import json

import pytest

from gryffin_ros.planner import Observation, Proposal
from gryffin_ros.storage import CampaignStore, StoreError

CONFIG = {"name": "c", "parameters": [{"name": "x", "type": "continuous", "low": 0, "high": 1}]}


def test_observations_survive_reopening_in_order(tmp_path):
    path = tmp_path / "c.sqlite"
    store = CampaignStore(path, CONFIG, "h1")
    store.add_proposals([Proposal("a", {"x": 0.1}, 1.0), Proposal("b", {"x": 0.2}, -1.0), Proposal("c", {"x": 0.3})])
    store.add_observation(Observation({"x": 0.2}, {"y": 2.0}, "b", {"note": "ok"}), raw='{"raw": 1}')
    store.add_observation(Observation({"x": 0.1}, {"y": None}, "a"))
    # no close(): what add_observation returned is on disk, as after a crash
    reopened = CampaignStore(path, CONFIG, "h1")
    assert [o.experiment_id for o in reopened.observations()] == ["b", "a"]
    assert reopened.observations()[1].failed
    assert [o.experiment_id for o in reopened.observations(skip=1)] == ["a"] and not reopened.observations(skip=2)
    assert [p.experiment_id for p in reopened.pending()] == ["c"]
    assert reopened.get_meta("config_hash") == "h1"


def test_duplicate_experiment_is_refused(tmp_path):
    store = CampaignStore(tmp_path / "c.sqlite", CONFIG, "h1")
    store.add_observation(Observation({"x": 0.2}, {"y": 2.0}, "b"))
    with pytest.raises(StoreError, match="already reported"):
        store.add_observation(Observation({"x": 0.3}, {"y": 3.0}, "b"))
    assert len(store.observations()) == 1


def test_another_config_is_refused(tmp_path):
    CampaignStore(tmp_path / "c.sqlite", CONFIG, "h1")
    with pytest.raises(StoreError, match="belongs to a different config"):
        CampaignStore(tmp_path / "c.sqlite", CONFIG, "h2")


def test_export_csv_and_json(tmp_path):
    store = CampaignStore(tmp_path / "c.sqlite", CONFIG, "h1")
    store.add_observation(Observation({"x": 0.2}, {"y": 2.0}, "b", {"X0": 0.5}))
    store.add_observation(Observation({"x": 0.4}, {"y": None}, "a"))
    assert store.export_csv(tmp_path / "out.csv") == 2
    rows = list(csv.DictReader(open(tmp_path / "out.csv")))
    assert rows[0] == {"seq": "1", "experiment_id": "b", "x": "0.2", "y": "2.0", "X0": "0.5"}
    assert rows[1]["y"] == ""
    store.export_json(tmp_path / "out.json")
    document = json.loads((tmp_path / "out.json").read_text())
    assert document["config"] == CONFIG and len(document["observations"]) == 2
    assert CampaignStore.open_existing(tmp_path / "c.sqlite").count_observations() == 2


def test_open_existing_refuses_other_files(tmp_path):
    (tmp_path / "x.sqlite").write_text("not a database")
    with pytest.raises(StoreError):
        CampaignStore.open_existing(tmp_path / "x.sqlite")
    with pytest.raises(StoreError, match="no campaign store"):
        CampaignStore.open_existing(tmp_path / "missing.sqlite")
