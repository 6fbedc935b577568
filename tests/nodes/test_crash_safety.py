"""Crash safety: the planner node is SIGKILLed at random moments of a closed-loop campaign and restarted on the same
store. No acknowledged observation is lost, no experiment is proposed twice, the campaign reaches its budget, and
the shared memory of the killed nodes is cleaned afterwards."""

import os
import random
import sqlite3
import time
from pathlib import Path

from tests import fastdds_shm

from .conftest import HANG_S, start_emulator

BUDGET = 24
KILLS = 5


def stored(path: Path) -> tuple[list[str], list[str]]:
    with sqlite3.connect(path) as db:
        observed = [r[0] for r in db.execute("SELECT experiment_id FROM observations ORDER BY seq")]
        proposed = [r[0] for r in db.execute("SELECT experiment_id FROM proposals")]
    return observed, proposed


def wait_for_observations(path: Path, count: int) -> None:
    """Until the store holds `count` observations; fails only when none is added for HANG_S (a stalled campaign)."""
    seen, deadline = -1, 0.0
    while (n := len(stored(path)[0])) < count:
        if n != seen:
            seen, deadline = n, time.monotonic() + HANG_S
        assert time.monotonic() < deadline, f"campaign stalled at {n} observations"
        time.sleep(0.2)


def test_sigkilled_planner_resumes_without_losing_or_repeating_anything(client, start_planner, supervisor,
                                                                        tmp_path):
    held: set[str] = set()  # the shared memory of this test's nodes (a parallel worker has its own)
    store = tmp_path / "crash.sqlite"
    emulator = start_emulator(supervisor, tmp_path, "-p", "seed:=3", "-p", "experiment_time_s:=0.05", "-p",
                              "objectives:=[X1_X2]")
    rng = random.Random(7)
    acknowledged: set[str] = set()
    try:
        planner = start_planner(storage=str(store), batch_size=2, seed=5)
        for _ in range(KILLS):
            # a random moment of the campaign, counted in its progress (0-2 more stored observations, then up to a
            # second more), not in seconds: on a slow machine seconds alone would land every kill in the first ask
            wait_for_observations(store, len(stored(store)[0]) + rng.randint(0, 2))
            time.sleep(rng.uniform(0.0, 1.0))
            held |= fastdds_shm.held_by(planner.process.pid)
            planner.process.kill()  # SIGKILL: no shutdown code runs
            planner.process.wait()
            with client.lock:
                acknowledged |= {e["experiment_id"] for e in client.events if e["type"] == "observation_accepted"}
            planner = start_planner(storage=str(store), batch_size=2, seed=5)
        wait_for_observations(store, BUDGET)
        with client.lock:
            acknowledged |= {e["experiment_id"] for e in client.events if e["type"] == "observation_accepted"}
    finally:
        held |= fastdds_shm.held_by(emulator.pid)
        supervisor.stop()
    observed, proposed = stored(store)
    assert acknowledged and acknowledged <= set(observed), "an acknowledged observation was lost"
    assert len(observed) == len(set(observed))
    assert set(observed) <= set(proposed)
    assert len(proposed) == len(set(proposed))
    status = client.status()
    assert status["n_observations"] >= BUDGET
    fastdds_shm.clean()  # the killed nodes' ports and segments
    held = fastdds_shm.of_domain(held, int(os.environ["ROS_DOMAIN_ID"]))
    assert held, "the nodes' shared memory was not found"
    assert not fastdds_shm.zombies(held), "shared memory of dead nodes left behind"
