"""A campaign recorded into a ROS 2 bag (node parameter `record`), read back with `rosbags`, a reader this project did
not write: every message deserializes with the schemas in the bag, the observations are there as received, each
followed by its accept or reject event, and the accepted ones equal the store's; a SIGKILLed node leaves a complete
bag."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import yaml

from gryffin_ros.storage import CampaignStore

from ..bags import as_store, read_bag
from .conftest import FLOW_CONFIG, HANG_S
from .test_typed import lab, observation_of, wait_until  # noqa: F401 - lab is a fixture

NODE = "/gryffin_planner"
OBJECTIVES = ("X1_X2",)


def observations_of(path: Path) -> list[tuple[str, dict, dict]]:
    store = CampaignStore.open_existing(path)
    try:
        return [(o.experiment_id, o.params, o.objectives) for o in store.observations()]
    finally:
        store.close()


def config_of(path: Path) -> dict:
    store = CampaignStore.open_existing(path)
    try:
        return store.config
    finally:
        store.close()


def gryffin_ros(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gryffin_ros.cli", *args], capture_output=True, text=True,
                          timeout=HANG_S)


def test_the_bag_keys_are_the_importers():
    from gryffin_ros.cli import bag_import
    from gryffin_ros.nodes import recorder
    assert (recorder.CONFIG_KEY, recorder.CONFIG_DIR_KEY, recorder.SEED_KEY) == (
        bag_import.CONFIG_KEY, bag_import.CONFIG_DIR_KEY, bag_import.SEED_KEY)


def test_a_recorded_campaign_reads_back_with_rosbags_and_matches_the_store(lab, start_planner, tmp_path):  # noqa: F811
    bag = tmp_path / "campaign_bag"
    started_ns = time.time_ns()
    planner = start_planner(record=str(bag), auto_propose=False)
    outcome = lab.recommend_now(3)
    first, second, third = outcome.result.proposals
    lab.wait_matched()
    sent = [observation_of(first, {"X1_X2": 0.4}), observation_of(second, {"X1_X2": 0.4}, T=180.0),
            observation_of(second, {"X1_X2": 0.2}), observation_of(third, None)]
    for msg in sent:
        lab.observations.publish(msg)
    events = lab.observation_events(4)
    assert [e.type for e in events] == ["observation_accepted", "observation_rejected", "observation_accepted",
                                        "observation_accepted"]
    assert planner.stop() == 0
    ended_ns = time.time_ns()

    messages = read_bag(bag)
    topics = {topic: kind for topic, kind, _, _ in messages}
    assert topics[f"{NODE}/observations"] == "gryffin_ros_msgs/msg/Observation"
    assert topics[f"{NODE}/events"] == "gryffin_ros_msgs/msg/Event"
    assert topics[f"{NODE}/status"] == "gryffin_ros_msgs/msg/CampaignStatus"
    stamps = [t for _, _, t, _ in messages]
    assert stamps == sorted(stamps) and started_ns <= stamps[0] and stamps[-1] <= ended_ns
    metadata = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert metadata["message_count"] == len(messages) and metadata["storage_identifier"] == "mcap"

    # the observations as received, in order, each judged by the event that follows it
    received = [m for topic, _, _, m in messages if topic == f"{NODE}/observations"]
    assert [as_store(m, OBJECTIVES) for m in received] == [as_store(m, OBJECTIVES) for m in sent]
    judged = [(m.type, m.experiment_id) for topic, _, _, m in messages if topic == f"{NODE}/events"
              and m.type.startswith("observation_")]
    assert judged == [(e.type, e.experiment_id) for e in events]
    accepted = [as_store(m, OBJECTIVES) for m, (kind, _) in zip(received, judged) if kind == "observation_accepted"]

    stored = observations_of(tmp_path / "campaign.sqlite")
    assert accepted == stored
    last_status = [m for topic, _, _, m in messages if topic == f"{NODE}/status"][-1]
    assert (last_status.n_observations, last_status.n_failed) == (3, 1)

    # back to a campaign: `gryffin-ros import` rebuilds the store from the bag alone (config and seed in its metadata)
    imported = tmp_path / "imported.sqlite"
    result = gryffin_ros("import", str(bag), "--out", str(imported))
    assert result.returncode == 0, result.stderr
    assert observations_of(imported) == stored
    assert config_of(imported) == config_of(tmp_path / "campaign.sqlite")
    # a bag without the config (recorded by something else) needs --config, and says so
    metadata_path = bag / "metadata.yaml"
    metadata = yaml.safe_load(metadata_path.read_text())
    metadata["rosbag2_bagfile_information"]["custom_data"] = None
    metadata_path.write_text(yaml.safe_dump(metadata))
    refused = gryffin_ros("import", str(bag), "--out", str(tmp_path / "again.sqlite"))
    assert refused.returncode == 2 and "give it with --config" in refused.stderr
    assert not (tmp_path / "again.sqlite").exists()
    config = tmp_path / "config.yaml"
    config.write_text(yaml.safe_dump(FLOW_CONFIG))
    again = gryffin_ros("import", str(bag), "--out", str(tmp_path / "again.sqlite"), "--config", str(config))
    assert again.returncode == 0, again.stderr
    assert observations_of(tmp_path / "again.sqlite") == stored


def test_a_killed_node_leaves_a_complete_bag(lab, start_planner, tmp_path):  # noqa: F811
    bag = tmp_path / "killed_bag"
    planner = start_planner(record=str(bag), auto_propose=False)
    proposals = lab.recommend_now(2).result.proposals
    lab.wait_matched()
    for proposal in proposals:
        lab.observations.publish(observation_of(proposal, {"X1_X2": 0.3}))
    lab.observation_events(2)
    ids = {p.experiment_id for p in proposals}

    def on_disk():
        try:
            messages = read_bag(bag)
        except Exception:  # noqa: BLE001 - not there yet (the first write) is the only expected case
            return None
        accepted = {m.experiment_id for topic, _, _, m in messages
                    if topic == f"{NODE}/events" and m.type == "observation_accepted"}
        return messages if accepted >= ids else None
    wait_until(on_disk, "the accepted observations in the bag on disk", HANG_S)
    planner.process.send_signal(signal.SIGKILL)
    planner.process.wait(timeout=HANG_S)
    messages = read_bag(bag)  # complete: opens and deserializes without the writer's close
    assert {m.experiment_id for topic, _, _, m in messages if topic == f"{NODE}/observations"} == ids


def test_a_record_folder_that_exists_is_refused(start_planner, tmp_path):
    taken = tmp_path / "taken"
    taken.mkdir()
    planner = start_planner(record=str(taken), wait=False)
    assert planner.process.wait(timeout=HANG_S) == 2
    assert f"record: {taken} already exists" in planner.output()
    assert list(taken.iterdir()) == []
