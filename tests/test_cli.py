"""`gryffin-ros campaign` end to end: both nodes as real processes over DDS, then CSV, PNG and store on disk."""

import csv
import json
import re
import signal
import subprocess
import sys

import pytest

from gryffin_ros.nodes.rosenv import ros_environment
from gryffin_ros.storage import CampaignStore

from .bags import as_store, judged_observations, read_bag

# Deadlines only catch hangs: many times what a step takes on a busy 2-core machine (the 12-experiment campaign over
# ROS below takes about 20 s there, Ctrl-C to exit a few), so a slow machine waits longer but never fails.
HANG_S = 600


def flow_feasible(params):
    fc, fs = params["F_C"], params["F_S"]
    return 30 < fc + fs < 310 and fc < 2 * fs and fs < 2 * fc


def stored(path):
    """Every observation of a store at full precision (the CSV rounds to 6 significant digits)."""
    store = CampaignStore.open_existing(path)
    try:
        return store.observations()
    finally:
        store.close()


def gryffin_ros(*args, timeout=HANG_S):
    return subprocess.run([sys.executable, "-m", "gryffin_ros.cli", *args], capture_output=True, text=True,
                          timeout=timeout, env=ros_environment())


@pytest.mark.ros
def test_closed_loop_campaign_over_ros(tmp_path):
    out = tmp_path / "run"
    result = gryffin_ros("campaign", "--budget", "12", "--seed", "4", "--out", str(out), "--record")
    assert result.returncode == 0, result.stdout + result.stderr
    done = [int(n) for n in re.findall(r"(\d+)/12 experiments", result.stdout)]
    assert done and done[-1] >= 12
    rows = list(csv.DictReader(open(out / "experiments.csv")))
    observations = stored(out / "campaign.sqlite")
    assert len(rows) == len(observations) >= 12
    assert all(flow_feasible(o.params) for o in observations)
    assert {"F_C (uL/min)", "F_S (uL/min)", "T (degC)", "X1_X2 (mole fraction)", "cost ($/min)", "failed", "strategy",
            "surrogate", "X0", "X1", "X2", "X3"} <= set(rows[0])
    assert (out / "best_so_far.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    export = gryffin_ros("export", str(out / "campaign.sqlite"), "--json", str(tmp_path / "all.json"))
    assert export.returncode == 0, export.stderr
    assert len(json.loads((tmp_path / "all.json").read_text())["observations"]) == len(rows)

    # --record: the planner node's bag, read by rosbags; its accepted observations are the store's
    messages = read_bag(out / "bag")
    judged = judged_observations(messages)
    accepted = [as_store(m, ("X1_X2", "cost")) for m, event in judged if event == "observation_accepted"]
    kept = [(o.experiment_id, o.params, o.objectives) for o in observations]
    assert accepted == kept[:len(accepted)] and len(accepted) >= 12
    # what the node stored as it stopped, after its events were no longer sent, was received all the same
    received = [as_store(m, ("X1_X2", "cost")) for topic, _, _, m in messages
                if topic == "/gryffin_planner/observations"]
    assert all(o in received for o in kept[len(accepted):])


@pytest.fixture(scope="module")
def api_campaign(tmp_path_factory):
    """One 8-experiment campaign through the Python API (--no-ros), shared by the tests that read its folder."""
    out = tmp_path_factory.mktemp("api_campaign")
    result = gryffin_ros("campaign", "--no-ros", "--budget", "8", "--seed", "1", "--out", str(out))
    assert result.returncode == 0, result.stderr
    return out


def test_campaign_without_ros_uses_the_same_store_format(api_campaign):
    observations = stored(api_campaign / "campaign.sqlite")
    assert len(observations) == 8 and all(flow_feasible(o.params) for o in observations)
    rows = list(csv.DictReader(open(api_campaign / "experiments.csv")))
    assert [row["experiment_id"] for row in rows] == [o.experiment_id for o in observations]


def test_export_without_options_writes_both_files_next_to_the_store(api_campaign):
    export = gryffin_ros("export", str(api_campaign / "campaign.sqlite"))
    assert export.returncode == 0, export.stderr
    rows = list(csv.DictReader(open(api_campaign / "campaign.csv")))
    document = json.loads((api_campaign / "campaign.json").read_text())
    assert len(rows) == len(document["observations"]) == 8


def test_dashboard_command_serves_a_store_until_ctrl_c(api_campaign, tmp_path):
    import urllib.request
    process = subprocess.Popen([sys.executable, "-m", "gryffin_ros.cli", "dashboard",
                                str(api_campaign / "campaign.sqlite"), "--port", "0"], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True)
    try:
        line = process.stdout.readline()  # the URL comes first
        url = re.search(r"(http://127\.0\.0\.1:\d+/)", line).group(1)
        with urllib.request.urlopen(url + "api/campaign", timeout=HANG_S) as response:
            assert len(json.loads(response.read())["experiments"]) == 8
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=HANG_S) == 0
    finally:
        process.kill()
    missing = gryffin_ros("dashboard", str(tmp_path / "nothing.sqlite"))
    assert missing.returncode == 2 and "no campaign store" in missing.stderr



def test_record_without_the_nodes_is_refused_with_the_reason():
    result = gryffin_ros("campaign", "--no-ros", "--record", "--budget", "1")
    assert result.returncode == 2 and "--record records the planner node's messages" in result.stderr
