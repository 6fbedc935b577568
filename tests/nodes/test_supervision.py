"""`gryffin-ros campaign` as an operator stops it: SIGINT (Ctrl-C), SIGTERM (systemd, a CI runner, `kill`), SIGHUP
(a closed terminal) and SIGKILL of the command. Its planner and emulator nodes are real processes over DDS; whether
they still run is read from /proc, not from logs. Every observation the planner acknowledged (observation_accepted,
heard by this test's lab client) is in the store, and a rerun with the same --out continues the campaign."""

from __future__ import annotations

import csv
import os
import signal
import sqlite3
import subprocess
import sys
import time

import pytest

from tests import fastdds_shm, proc

from .conftest import HANG_S, node_env

# after SIGKILL of the command its nodes are on their own: a grace period (ORPHAN_GRACE_S, 5 s) and the time a busy
# machine takes to end a process bound when they are gone; this only catches nodes that never leave
ORPHANS_GONE_S = 60.0


def stored_ids(out) -> list[str]:
    try:
        with sqlite3.connect(out / "campaign.sqlite") as db:
            return [row[0] for row in db.execute("SELECT experiment_id FROM observations ORDER BY seq")]
    except sqlite3.OperationalError:  # not created yet
        return []


def start_campaign(tmp_path, out) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "gryffin_ros.cli", "campaign", "--budget", "400", "--seed", "3",
                             "--experiment-time", "0.05", "--out", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=node_env(tmp_path))


def accepted(client) -> set[str]:
    with client.lock:
        return {e["experiment_id"] for e in client.events if e["type"] == "observation_accepted"}


def nodes_once_running(campaign: subprocess.Popen, client, at_least: int) -> set[tuple[int, int]]:
    """The command's node processes, once the planner has acknowledged `at_least` more observations."""
    before = len(accepted(client))
    deadline = time.monotonic() + HANG_S
    while len(accepted(client)) < before + at_least:
        assert campaign.poll() is None, campaign.communicate()[0]
        assert time.monotonic() < deadline, "the campaign made no progress"
        time.sleep(0.05)
    nodes = proc.children(campaign.pid)
    names = sorted(proc.command_line(n) for n in nodes)
    assert len(nodes) == 2 and "planner_node" in names[0] + names[1] and "emulator_node" in names[0] + names[1]
    return nodes


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGHUP])
def test_a_stop_signal_stops_both_nodes_keeps_every_acknowledged_result_and_a_rerun_continues(
        sig, client, tmp_path):
    out = tmp_path / "run"
    campaign = start_campaign(tmp_path, out)
    nodes = nodes_once_running(campaign, client, 3)
    held = fastdds_shm.of_domain(set().union(*(fastdds_shm.held_by(pid) for pid, _ in nodes)),  # the nodes' own
                                 int(os.environ["ROS_DOMAIN_ID"]))
    campaign.send_signal(sig)
    output, _ = campaign.communicate(timeout=HANG_S)
    assert campaign.returncode == 128 + sig, output
    assert not {n for n in nodes if proc.running(n)}, "a node outlived the command"
    assert "planner node (pid" in output and "emulator node (pid" in output  # how each ended is said
    ids = stored_ids(out)
    assert accepted(client) <= set(ids), "an acknowledged observation is missing from the store"
    rows = list(csv.DictReader(open(out / "experiments.csv")))
    assert len(rows) == len(ids) > 0
    assert held and not fastdds_shm.zombies(held), "shared memory of the stopped nodes left in /dev/shm"
    if sig != signal.SIGTERM:
        return
    rerun = start_campaign(tmp_path, out)  # the same --out: the same store, continued
    nodes_once_running(rerun, client, 2)
    rerun.send_signal(signal.SIGINT)
    output, _ = rerun.communicate(timeout=HANG_S)
    assert rerun.returncode == 130, output
    again = stored_ids(out)
    assert again[:len(ids)] == ids and len(again) >= len(ids) + 2


def test_nodes_leave_on_their_own_when_the_command_is_killed(client, tmp_path):
    out = tmp_path / "run"
    campaign = start_campaign(tmp_path, out)
    nodes = nodes_once_running(campaign, client, 2)
    campaign.kill()  # SIGKILL: the command stops nothing itself
    campaign.wait()
    killed_at = time.monotonic()
    left = proc.wait_gone(nodes, ORPHANS_GONE_S)
    assert not left, [proc.command_line(n) for n in left]
    gone_after = time.monotonic() - killed_at
    assert accepted(client) <= set(stored_ids(out)), "an acknowledged observation is missing from the store"
    print(f"nodes gone {gone_after:.1f} s after SIGKILL of the command")
