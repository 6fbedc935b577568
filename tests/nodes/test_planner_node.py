"""The planner node over real DDS: services, observation events, restart on the same store, plugins."""

import json
import os
import re
import sqlite3
import subprocess
import sys
import time
import urllib.request

from gryffin_ros import messages

from .conftest import FLOW_CONFIG, HANG_S, flow_feasible, node_env


def observation(proposal, value=0.5, **changes):
    return {"experiment_id": proposal["experiment_id"], "params": {**proposal["params"], **changes},
            "objectives": {"X1_X2": value}}


def stored_ids(path):
    with sqlite3.connect(path) as db:
        return [row[0] for row in db.execute("SELECT experiment_id FROM observations ORDER BY seq")]


def test_recommend_round_trip_and_observation_accepted(client, start_planner, tmp_path):
    start_planner(auto_propose=False)
    response = client.recommend()
    assert response.success, response.message
    document = json.loads(response.message)
    messages.check("proposals", document)
    (proposal,) = document["proposals"]
    assert flow_feasible(proposal["params"])
    client.wait_matched()
    before = len(client.wait_events(0))
    client.publish(observation(proposal))
    event = client.wait_events(before + 1)[-1]
    assert event == {"type": "observation_accepted", "experiment_id": proposal["experiment_id"]}
    status = client.status()
    messages.check("status", status)
    assert (status["n_observations"], status["n_pending"]) == (1, 0)
    assert stored_ids(tmp_path / "campaign.sqlite") == [proposal["experiment_id"]]


def test_every_bad_observation_gets_a_specific_reason_and_nothing_is_stored(client, start_planner, tmp_path):
    start_planner(auto_propose=False)
    first, second = (json.loads(client.recommend().message)["proposals"][0] for _ in range(2))
    client.wait_matched()
    bad = [
        ("{not json", "malformed JSON"),
        ({"experiment_id": "x", "params": {"F_C": 1}}, "objectives"),
        (observation(first, F_X=3.0), "unknown parameter(s) ['F_X']"),
        (observation(first, T=180.0), "'T' = 180.0 is above its upper bound 150.0"),
        (observation(first, F_C=150.0, F_S=10.0), "violate the known constraint"),
        ({**observation(first), "experiment_id": "never-proposed"}, "unknown experiment_id 'never-proposed'"),
        ({**observation(first), "objectives": {"X1_X2": "high"}}, "invalid at objectives/X1_X2"),
    ]
    start = len(client.wait_events(0))
    for payload, _ in bad:
        client.publish(payload)
    client.publish(observation(first))
    client.publish(observation(first, value=0.9))  # duplicate: the first report stands
    client.publish(observation(second, value=None) | {"objectives": None})  # a failed experiment is data
    events = client.wait_events(start + len(bad) + 3)[start:]
    for (payload, reason), event in zip(bad, events):
        assert event["type"] == "observation_rejected", (payload, event)
        assert reason in event["reason"], (reason, event)
        # the refusal names the experiment whenever the message does, schema violations included
        named = payload.get("experiment_id") if isinstance(payload, dict) else None
        assert event.get("experiment_id") == named, (payload, event)
    assert events[len(bad)]["type"] == "observation_accepted", events[len(bad)]
    assert events[len(bad) + 1]["type"] == "observation_rejected"
    assert "already reported" in events[len(bad) + 1]["reason"]
    assert events[len(bad) + 2]["type"] == "observation_accepted"
    status = client.status()
    assert (status["n_observations"], status["n_failed"], status["n_pending"]) == (2, 1, 0)
    assert stored_ids(tmp_path / "campaign.sqlite") == [first["experiment_id"], second["experiment_id"]]
    assert client.recommend().success  # still serving


def test_restart_on_the_same_store_resumes_and_refuses_another_config(client, start_planner, tmp_path):
    planner = start_planner(auto_propose=False)
    proposals = [json.loads(client.recommend().message)["proposals"][0] for _ in range(4)]
    client.wait_matched()
    start = len(client.wait_events(0))
    for proposal in proposals[:3]:
        client.publish(observation(proposal, value=0.3))
    client.wait_events(start + 3)
    assert planner.stop() == 0
    restarted = start_planner(auto_propose=False)
    deadline = time.monotonic() + HANG_S
    while True:  # the old node's service may still be discovered for a moment
        status = client.status()
        if status["n_pending"] == 1 or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    assert (status["n_observations"], status["n_pending"]) == (3, 1)
    client.wait_matched()  # the new node's subscription: a message sent before it matches is lost (volatile QoS)
    client.publish(observation(proposals[3], value=0.8))
    client.wait_events(start + 4)
    assert client.status()["best"]["objectives"] == {"X1_X2": 0.8}
    # an operator starts a second node on the same store: refused at once, naming the holder; the first serves on
    second = start_planner(wait=False, auto_propose=False)
    assert second.process.wait(timeout=HANG_S) == 2
    assert f"is in use by pid {restarted.process.pid}" in second.output()
    assert client.status()["n_observations"] == 4
    assert restarted.process.poll() is None
    assert restarted.stop() == 0
    assert "Traceback" not in restarted.output()  # a clean shutdown: no callback publishing into a dead context
    other = {**FLOW_CONFIG, "constraints": ["F_C + F_S <= 100"]}
    refused = start_planner(other, wait=False, auto_propose=False)
    assert refused.process.wait(timeout=HANG_S) == 2
    assert "different config" in refused.output()


def test_auto_propose_publishes_the_next_batch_when_all_have_reported(client, start_planner):
    start_planner(batch_size=2)
    latest = client.wait_proposals(1)[-1]
    assert len(latest["proposals"]) == 2
    client.wait_matched()
    for proposal in latest["proposals"]:
        client.publish(observation(proposal))
    following = client.wait_proposals(2)[-1]
    assert following["n_observations"] == 2
    assert {p["experiment_id"] for p in following["proposals"]}.isdisjoint(
        {p["experiment_id"] for p in latest["proposals"]})


def test_third_party_plugin_loads_and_a_raising_plugin_is_reported(client, start_planner):
    config = {**FLOW_CONFIG, "constraints": [{"plugin": "test_max_sum", "options": {"names": ["F_C", "F_S"],
                                                                                  "limit": 60}}]}
    start_planner(config, auto_propose=False)
    for _ in range(3):
        (proposal,) = json.loads(client.recommend().message)["proposals"]
        assert proposal["params"]["F_C"] + proposal["params"]["F_S"] <= 60
    planner = start_planner({**FLOW_CONFIG, "name": "exploding", "constraints": [{"plugin": "test_exploding"}]},
                            wait=False, auto_propose=False, storage="\":memory:\"")
    assert planner.process.wait(timeout=HANG_S) == 2  # V_C is estimated at start-up: the broken plugin stops it there
    assert "'test_exploding' raised RuntimeError: interlock controller unreachable" in planner.output()


def test_the_config_chooses_the_optimizer_unless_the_node_parameter_overrides_it(client, start_planner, tmp_path):
    def logged(node, text: str) -> bool:  # the start-up line may follow the first status by a moment
        deadline = time.monotonic() + HANG_S
        while text not in node.output() and time.monotonic() < deadline:
            time.sleep(0.05)
        return text in node.output()

    config = {**FLOW_CONFIG, "general": {"acquisition_optimizer": "genetic"}}
    node = start_planner(config, storage=str(tmp_path / "a.sqlite"))
    assert logged(node, "acquisition optimizer genetic")
    # what a lab client must match to see the node is logged at start-up
    assert logged(node, f"ROS_DOMAIN_ID={os.environ['ROS_DOMAIN_ID']}, RMW_IMPLEMENTATION=rmw_fastrtps_cpp, "
                        "ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST")
    assert node.stop() == 0
    node = start_planner(config, storage=str(tmp_path / "b.sqlite"), acquisition_optimizer="adam")
    assert logged(node, "acquisition optimizer adam")


def test_bad_start_up_parameters_exit_with_a_message(tmp_path):
    env = node_env(tmp_path)
    result = subprocess.run([sys.executable, "-m", "gryffin_ros.nodes.planner_node"], env=env, capture_output=True,
                            text=True, timeout=HANG_S)
    assert result.returncode == 2 and "parameter 'config' is required" in result.stderr
    config = tmp_path / "contradiction.json"
    config.write_text(json.dumps({**FLOW_CONFIG, "constraints": ["F_C < 10", "F_C > 20"]}))
    result = subprocess.run([sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-p",
                             f"config:={config}", "-p", "storage:=\":memory:\""], env=env, capture_output=True,
                            text=True, timeout=HANG_S)
    assert result.returncode == 2 and "no point satisfying the known constraints" in result.stderr
    config.write_text(json.dumps({**FLOW_CONFIG, "parameters": [*FLOW_CONFIG["parameters"], SOLVENT],
                                  "constraints": ["T < 66 if solvent == 'thf' else T < 150"]}))
    result = subprocess.run([sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-p",
                             f"config:={config}", "-p", "storage:=\":memory:\""], env=env, capture_output=True,
                            text=True, timeout=HANG_S)
    assert result.returncode == 2 and "'thf' is not an option of 'solvent'" in result.stderr
    assert "did you mean 'THF'?" in result.stderr


SOLVENT = {"name": "solvent", "type": "categorical", "options": ["THF", "DMF"]}


def test_a_constraint_that_excludes_nothing_is_logged_and_in_the_status(client, start_planner):
    config = {**FLOW_CONFIG, "parameters": [*FLOW_CONFIG["parameters"], SOLVENT],
              "constraints": [*FLOW_CONFIG["constraints"], "T < 160 if solvent == 'THF' else T < 200"]}
    node = start_planner(config, auto_propose=False)
    [warning] = client.status()["warnings"]
    assert "'T < 160 if solvent == 'THF' else T < 200' excludes no point" in warning
    assert warning in node.output()


BLEND_CONFIG = {
    "name": "blend_test",
    "parameters": [{"name": n, "type": "continuous", "low": 0.0, "high": 1.0} for n in ("water", "ethanol", "dmso")]
    + [{"name": "T", "type": "continuous", "low": 20.0, "high": 90.0}],
    "objectives": [{"name": "yield", "goal": "max"}],
    "constraints": [{"mixture": {"components": ["water", "ethanol", "dmso"], "bounds": {"dmso": [0.0, 0.6]}}},
                    "T < 100 - 22 * ethanol"],
}


def test_mixture_campaign_over_ros_proposes_exact_blends_and_names_a_broken_one(client, start_planner, tmp_path):
    start_planner(BLEND_CONFIG, auto_propose=False)
    proposals = [json.loads(client.recommend().message)["proposals"][0] for _ in range(3)]
    for proposal in proposals:
        p = proposal["params"]
        assert list(p) == ["water", "ethanol", "dmso", "T"]
        assert abs(p["water"] + p["ethanol"] + p["dmso"] - 1.0) <= 1e-9 and p["dmso"] <= 0.6
    client.wait_matched()
    start = len(client.wait_events(0))
    first, second, third = proposals
    client.publish({"experiment_id": first["experiment_id"], "params": first["params"], "objectives": {"yield": 40.0}})
    broken = {**second["params"], "dmso": second["params"]["dmso"] + 0.05}
    client.publish({"experiment_id": second["experiment_id"], "params": broken, "objectives": {"yield": 50.0}})
    missing = {k: v for k, v in third["params"].items() if k != "dmso"}
    client.publish({"experiment_id": third["experiment_id"], "params": missing, "objectives": {"yield": 50.0}})
    events = client.wait_events(start + 3)[start:]
    assert events[0]["type"] == "observation_accepted", events
    assert events[1]["type"] == "observation_rejected" and "water + ethanol + dmso == 1.0" in events[1]["reason"]
    assert events[2]["type"] == "observation_rejected" and "missing parameter(s) ['dmso']" in events[2]["reason"]
    assert stored_ids(tmp_path / "campaign.sqlite") == [first["experiment_id"]]


def test_gp_campaign_over_ros_records_the_surrogate_in_messages_and_store(client, start_planner, tmp_path):
    start_planner({**FLOW_CONFIG, "general": {"surrogate": "gp"}}, auto_propose=False)
    client.wait_matched()
    start = len(client.wait_events(0))
    # the first proposal is a random pick, the next four the initial design (random feasible points until the GP has
    # five distinct results), then the GP's
    expected = [None] + ["random"] * 4 + ["gp"] * 2
    for i, surrogate in enumerate(expected):
        document = json.loads(client.recommend().message)
        messages.check("proposals", document)
        (proposal,) = document["proposals"]
        assert flow_feasible(proposal["params"])
        assert proposal.get("meta", {}).get("surrogate") == surrogate
        client.publish(observation(proposal, value=0.2 + 0.1 * i))
        client.wait_events(start + i + 1)
    with sqlite3.connect(tmp_path / "campaign.sqlite") as db:
        stored = [json.loads(meta or "{}").get("surrogate") for (meta,) in
                  db.execute("SELECT meta FROM proposals ORDER BY created, rowid")]
    assert stored == expected


def test_the_node_serves_its_campaigns_dashboard_when_asked(client, start_planner, tmp_path):
    node = start_planner(auto_propose=False, dashboard_port=0)
    deadline = time.monotonic() + HANG_S
    while not re.search(r"dashboard: (http://127\.0\.0\.1:\d+/)", node.output()):
        assert time.monotonic() < deadline and node.process.poll() is None, node.output()
        time.sleep(0.05)
    url = re.search(r"dashboard: (http://127\.0\.0\.1:\d+/)", node.output()).group(1)
    client.recommend()
    with urllib.request.urlopen(url + "api/campaign", timeout=HANG_S) as response:
        data = json.loads(response.read())
    assert data["campaign"] == FLOW_CONFIG["name"] and len(data["pending"]) == 1
    assert node.stop() == 0
    refused = start_planner(wait=False, auto_propose=False, dashboard_port=0, storage="\":memory:\"")
    assert refused.process.wait(timeout=HANG_S) == 2 and "the dashboard reads the campaign store" in refused.output()
