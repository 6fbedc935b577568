"""Crash safety: the planner node is SIGKILLed at random moments of a closed-loop campaign and restarted on the same
store. No acknowledged observation is lost, no experiment is proposed twice, the campaign reaches its budget, and
the shared memory of the killed nodes is cleaned afterwards."""

import random
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

from .conftest import node_env

BUDGET = 24
KILLS = 5


def stored(path: Path) -> tuple[list[str], list[str]]:
    with sqlite3.connect(path) as db:
        observed = [r[0] for r in db.execute("SELECT experiment_id FROM observations ORDER BY seq")]
        proposed = [r[0] for r in db.execute("SELECT experiment_id FROM proposals")]
    return observed, proposed


def test_sigkilled_planner_resumes_without_losing_or_repeating_anything(client, start_planner, tmp_path):
    store = tmp_path / "crash.sqlite"
    emulator = subprocess.Popen([sys.executable, "-m", "gryffin_ros.nodes.emulator_node", "flow_reactor", "--ros-args",
                                 "-p", "seed:=3", "-p", "experiment_time_s:=0.05", "-p", "objectives:=[X1_X2]"],
                                env=node_env(tmp_path),
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rng = random.Random(7)
    acknowledged: set[str] = set()
    try:
        planner = start_planner(storage=str(store), batch_size=2, seed=5)
        for _ in range(KILLS):
            time.sleep(rng.uniform(0.3, 1.5))
            planner.process.kill()  # SIGKILL: no shutdown code runs
            planner.process.wait()
            with client.lock:
                acknowledged |= {e["experiment_id"] for e in client.events if e["type"] == "observation_accepted"}
            planner = start_planner(storage=str(store), batch_size=2, seed=5)
        deadline = time.monotonic() + 120
        while len(stored(store)[0]) < BUDGET:
            assert time.monotonic() < deadline, f"campaign stalled at {len(stored(store)[0])} observations"
            time.sleep(0.2)
        with client.lock:
            acknowledged |= {e["experiment_id"] for e in client.events if e["type"] == "observation_accepted"}
    finally:
        emulator.kill()
        emulator.wait()
    observed, proposed = stored(store)
    assert acknowledged and acknowledged <= set(observed), "an acknowledged observation was lost"
    assert len(observed) == len(set(observed))
    assert set(observed) <= set(proposed)
    assert len(proposed) == len(set(proposed))
    status = client.status()
    assert status["n_observations"] >= BUDGET
    tool = Path(sys.executable).with_name("fastdds")
    subprocess.run([str(tool), "shm", "clean"], capture_output=True, timeout=60)  # the killed nodes' segments
    again = subprocess.run([str(tool), "shm", "clean"], capture_output=True, text=True, timeout=60).stdout
    assert "0 zombie segments cleaned" in again
