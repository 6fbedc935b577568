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
    # no close(): what add_observation returned is on disk, as after a crash (read by a second connection)
    reopened = CampaignStore.open_existing(path)
    assert [o.experiment_id for o in reopened.observations()] == ["b", "a"]
    assert reopened.observations()[1].failed
    assert [o.experiment_id for o in reopened.observations(skip=1)] == ["a"] and not reopened.observations(skip=2)
    assert [p.experiment_id for p in reopened.pending()] == ["c"]
    assert reopened.get_meta("config_hash") == "h1"


def test_a_store_has_one_writer_readers_take_no_lock(tmp_path):
    path = tmp_path / "c.sqlite"
    writer = CampaignStore(path, CONFIG, "h1")
    with pytest.raises(StoreError, match="is in use by pid"):
        CampaignStore(path, CONFIG, "h1")
    reader = CampaignStore.open_existing(path)
    writer.add_observation(Observation({"x": 0.2}, {"y": 2.0}, "b"))
    assert reader.count_observations() == 1  # a reader follows the writer
    with pytest.raises(StoreError, match="for reading only"):
        reader.add_observation(Observation({"x": 0.3}, {"y": 2.0}, "c"))
    writer.close()
    CampaignStore(path, CONFIG, "h1").close()  # free again once the writer closed


def test_duplicate_experiment_is_refused(tmp_path):
    store = CampaignStore(tmp_path / "c.sqlite", CONFIG, "h1")
    store.add_observation(Observation({"x": 0.2}, {"y": 2.0}, "b"))
    with pytest.raises(StoreError, match="already reported"):
        store.add_observation(Observation({"x": 0.3}, {"y": 3.0}, "b"))
    assert len(store.observations()) == 1


def test_another_config_is_refused(tmp_path):
    CampaignStore(tmp_path / "c.sqlite", CONFIG, "h1").close()
    with pytest.raises(StoreError, match="belongs to a different config"):
        CampaignStore(tmp_path / "c.sqlite", CONFIG, "h2")


def test_a_changed_config_is_refused_saying_what_changed_and_how_to_carry_the_results_over(tmp_path):
    CampaignStore(tmp_path / "c.sqlite", CONFIG, "h1").close()
    changed = json.loads(json.dumps(CONFIG))
    changed["parameters"][0]["high"] = 2.0
    changed["general"] = {"batches": 2}
    with pytest.raises(StoreError) as refused:
        CampaignStore(tmp_path / "c.sqlite", changed, "h2")
    message = str(refused.value)
    assert "parameters.x.high: 1 -> 2.0" in message and "general added" in message
    assert "gryffin-ros export" in message and "accept_unsolicited" in message


def test_export_csv_and_json(tmp_path):
    config = {"name": "c", "parameters": [{"name": "x", "type": "continuous", "low": 0, "high": 1, "units": "mL"}],
              "objectives": [{"name": "y", "goal": "min", "units": "$/min"}]}
    store = CampaignStore(tmp_path / "c.sqlite", config, "h1")
    store.add_proposals([Proposal("b", {"x": 0.2}, -1.0, {"surrogate": "gp"})])
    store.add_observation(Observation({"x": 0.2}, {"y": 2.0 / 3.0}, "b", {"X0": 0.5, "y": 2.0 / 3.0}))
    store.add_observation(Observation({"x": 0.4}, {"y": None}, "a"))
    assert store.export_csv(tmp_path / "out.csv") == 2
    rows = list(csv.DictReader(open(tmp_path / "out.csv")))
    # units in the headers, 6 significant digits, what chose the point, failed or not; meta not repeating objectives
    assert rows[0] == {"seq": "1", "experiment_id": "b", "x (mL)": "0.2", "y ($/min)": "0.666667", "failed": "False",
                       "strategy": "-1.0", "surrogate": "gp", "X0": "0.5"}
    assert (rows[1]["y ($/min)"], rows[1]["failed"], rows[1]["strategy"], rows[1]["surrogate"]) == ("", "True", "", "")
    store.export_json(tmp_path / "out.json")
    document = json.loads((tmp_path / "out.json").read_text())
    assert document["config"] == config and len(document["observations"]) == 2
    assert document["observations"][0]["objectives"]["y"] == 2.0 / 3.0  # JSON keeps every digit
    assert CampaignStore.open_existing(tmp_path / "c.sqlite").count_observations() == 2


def test_open_existing_refuses_other_files(tmp_path):
    (tmp_path / "x.sqlite").write_text("not a database")
    with pytest.raises(StoreError):
        CampaignStore.open_existing(tmp_path / "x.sqlite")
    with pytest.raises(StoreError, match="no campaign store"):
        CampaignStore.open_existing(tmp_path / "missing.sqlite")


def test_proposal_meta_is_stored_and_old_stores_gain_the_column(tmp_path):
    import sqlite3
    path = tmp_path / "old.sqlite"
    with sqlite3.connect(path) as db:  # a store written before proposals had meta
        db.executescript(
            "CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);"
            "CREATE TABLE proposals (experiment_id TEXT PRIMARY KEY, params TEXT NOT NULL, strategy REAL,"
            " created REAL NOT NULL);"
            "INSERT INTO meta VALUES ('config', '{}'), ('config_hash', 'h1');"
            "INSERT INTO proposals VALUES ('old', '{\"x\": 0.5}', 1.0, 0.0);")
    store = CampaignStore(path, CONFIG, "h1")
    store.add_proposals([Proposal("new", {"x": 0.1}, None, {"surrogate": "gp",
                                                           "loo_rank_correlation": {"kde": 0.2, "gp": 0.9}})])
    store.close()
    reopened = CampaignStore(path, CONFIG, "h1")
    old, new = reopened.proposals()
    assert (old.experiment_id, old.meta, old.strategy) == ("old", {}, 1.0)
    assert new.meta == {"surrogate": "gp", "loo_rank_correlation": {"kde": 0.2, "gp": 0.9}}
    assert new.to_dict()["meta"]["surrogate"] == "gp" and "meta" not in old.to_dict()


def test_csv_export_carries_the_smiles_of_molecules_and_the_store_keeps_rdkit_values(tmp_path):
    config = {"name": "c", "parameters": [{"name": "solvent", "type": "categorical",
                                           "options": {"toluene": "Cc1ccccc1", "DMF": "CN(C)C=O"}}]}
    store = CampaignStore(tmp_path / "c.sqlite", config, "h1")
    store.add_molecule_values({("Cc1ccccc1", "weight"): 92.14, ("CN(C)C=O", "smarts:N"): 1.0})
    store.add_observation(Observation({"solvent": "DMF"}, {"y": 1.0}, "a"))
    store.export_csv(tmp_path / "out.csv")
    (row,) = csv.DictReader(open(tmp_path / "out.csv"))
    assert (row["solvent"], row["solvent SMILES"]) == ("DMF", "CN(C)C=O")
    assert list(row)[:4] == ["seq", "experiment_id", "solvent", "solvent SMILES"]
    store.close()
    assert CampaignStore.molecule_values_at(tmp_path / "c.sqlite") == {("Cc1ccccc1", "weight"): 92.14,
                                                                        ("CN(C)C=O", "smarts:N"): 1.0}
    assert CampaignStore.molecule_values_at(tmp_path / "none.sqlite") == {}
