"""`gryffin-ros campaign` end to end: both nodes as real processes over DDS, then CSV, PNG and store on disk."""

import csv
import json
import re
import signal
import sqlite3
import subprocess
import sys
import time

from gryffin_ros.rosenv import ros_environment
from gryffin_ros.storage import CampaignStore
from tests import fastdds_shm

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


def test_closed_loop_campaign_over_ros(tmp_path):
    out = tmp_path / "run"
    result = gryffin_ros("campaign", "--budget", "12", "--seed", "4", "--out", str(out))
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


def test_campaign_without_ros_uses_the_same_store_format(tmp_path):
    result = gryffin_ros("campaign", "--no-ros", "--budget", "8", "--seed", "1", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    observations = stored(tmp_path / "campaign.sqlite")
    assert len(observations) == 8 and all(flow_feasible(o.params) for o in observations)
    rows = list(csv.DictReader(open(tmp_path / "experiments.csv")))
    assert [row["experiment_id"] for row in rows] == [o.experiment_id for o in observations]


def test_export_without_options_writes_both_files_next_to_the_store(tmp_path):
    assert gryffin_ros("campaign", "--no-ros", "--budget", "3", "--seed", "1", "--out", str(tmp_path)).returncode == 0
    export = gryffin_ros("export", str(tmp_path / "campaign.sqlite"))
    assert export.returncode == 0, export.stderr
    rows = list(csv.DictReader(open(tmp_path / "campaign.csv")))
    document = json.loads((tmp_path / "campaign.json").read_text())
    assert len(rows) == len(document["observations"]) == 3


def test_ctrl_c_stops_both_nodes_and_keeps_the_results(tmp_path):
    fastdds_shm.clean()  # what crashed runs left before this test is not this test's business
    before = fastdds_shm.lock_files()
    process = subprocess.Popen([sys.executable, "-m", "gryffin_ros.cli", "campaign", "--budget", "500",
                                "--experiment-time", "0.05", "--out", str(tmp_path)], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, env=ros_environment())
    deadline = time.monotonic() + HANG_S
    while not (tmp_path / "campaign.sqlite").exists() or not _observations(tmp_path):
        assert time.monotonic() < deadline and process.poll() is None, "campaign made no progress"
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    output, _ = process.communicate(timeout=HANG_S)
    assert process.returncode == 130, output
    rows = list(csv.DictReader(open(tmp_path / "experiments.csv")))
    assert len(rows) == _observations(tmp_path) > 0
    children = subprocess.run(["pgrep", "-f", f"storage:={tmp_path}"], capture_output=True, text=True).stdout
    assert children.strip() == ""
    left = fastdds_shm.zombies(fastdds_shm.lock_files() - before)
    assert not left, f"shared memory of dead participants left in /dev/shm: {sorted(left)}"


def _observations(path):
    try:
        with sqlite3.connect(path / "campaign.sqlite") as db:
            return db.execute("SELECT COUNT(*) FROM observations").fetchone()[0]
    except sqlite3.OperationalError:
        return 0


def test_dashboard_command_serves_a_store_until_ctrl_c(tmp_path):
    import urllib.request
    assert gryffin_ros("campaign", "--no-ros", "--budget", "3", "--seed", "2", "--out", str(tmp_path)).returncode == 0
    process = subprocess.Popen([sys.executable, "-m", "gryffin_ros.cli", "dashboard", str(tmp_path / "campaign.sqlite"),
                                "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        line = process.stdout.readline()  # the URL comes first
        url = re.search(r"(http://127\.0\.0\.1:\d+/)", line).group(1)
        with urllib.request.urlopen(url + "api/campaign", timeout=HANG_S) as response:
            assert len(json.loads(response.read())["experiments"]) == 3
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=HANG_S) == 0
    finally:
        process.kill()
    missing = gryffin_ros("dashboard", str(tmp_path / "nothing.sqlite"))
    assert missing.returncode == 2 and "no campaign store" in missing.stderr

