"""benchmarks.regret_split: a campaign's regret split into its combination's gap and what it left within it."""

import csv
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks import from_scratch, portfolio_tasks, regret_split

ROOT = Path(__file__).resolve().parents[2]


def write_campaign(folder: Path, task, seed: int, rows: list[tuple[list, float | None]]) -> None:
    """A harness campaign file (the columns regret_split reads: the parameters and y, empty for a failure)."""
    (folder / task.name).mkdir(parents=True, exist_ok=True)
    with open(folder / task.name / f"gryffin_ros_default_seed{seed}.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["iter"] + [p.name for p in task.params] + ["y"])
        for k, (x, y) in enumerate(rows, 1):
            writer.writerow([k] + list(x) + ["" if y is None else y])


def test_a_campaign_on_a_worse_initiator_splits_into_its_combination_s_gap_and_what_it_left(tmp_path):
    task = portfolio_tasks.TASKS["m_raft"]()
    agent, initiator, solvent = task.agents.index, task.initiators.index, task.solvents.index
    aibn = (agent("DDMAT"), initiator("AIBN"), solvent("DMF"))
    cold = [*aibn, 5.09, 63.2, 11.9, 2.98]  # AIBN where a stuck campaign ended: 0.470
    worse = [agent("xanthate"), initiator("ACVA"), solvent("DMF"), 10.0, 70.0, 8.0, 2.0]
    write_campaign(tmp_path, task, 3, [(worse, task.objective(worse)), (cold, task.objective(cold)), (cold, None)])
    ((seed, x, best),) = regret_split.campaigns(tmp_path, task, "gryffin_ros_default")
    assert seed == 3 and best == pytest.approx(task.objective(cold)) and x[:3] == list(aibn)
    reference = from_scratch.REFERENCES["m_raft"]
    gap, within, combination = regret_split.Splitter(task).split(x, best, reference)
    assert combination == aibn
    # the parts add up to the regret (by construction, to rounding)
    assert gap + within == pytest.approx(best - reference, abs=1e-12)
    # AIBN's own best (SLSQP: 0.512 at 73.5 deg C, 11.6 agents per initiator) is at least as good as this feasible
    # point near it, and no better than the reference: the gap is AIBN's 0.012 and most of the regret is within
    near = [*aibn, 11.7, 73.5, 7.8, 2.8]
    assert task.feasible(near)
    assert 0.0 <= gap <= task.objective(near) - reference
    assert within > 2 * gap


def test_the_command_prints_each_campaign_and_refuses_a_folder_without_campaigns(tmp_path):
    task = portfolio_tasks.TASKS["m_raft"]()
    best = [task.agents.index("DDMAT"), task.initiators.index("ACVA"), task.solvents.index("DMF"), 11.0, 78.0, 7.5,
            2.76]
    write_campaign(tmp_path, task, 0, [(best, task.objective(best))])
    command = [sys.executable, "-m", "benchmarks.regret_split", "--task", "m_raft"]
    done = subprocess.run(command + ["--runs", str(tmp_path)], cwd=ROOT, capture_output=True, text=True, check=True)
    assert "seed 0:" in done.stdout and "1 campaigns" in done.stdout
    empty = subprocess.run(command + ["--runs", str(tmp_path / "none")], cwd=ROOT, capture_output=True, text=True)
    assert empty.returncode != 0 and "no campaigns" in empty.stderr
