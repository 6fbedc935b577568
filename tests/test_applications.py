"""The paper's two applications as shipped: configs load, the synthesizability lookup holds, short runs work."""

import csv
import subprocess
import sys

import pytest

from gryffin_ros.emulators import RedoxEmulator
from gryffin_ros.nodes.rosenv import ros_environment
from gryffin_ros.paths import share_path
from gryffin_ros.planner import Planner

EXAMPLES = share_path("examples")
BEST_REDOX = {"r1_label": "R1_0", "r3_label": "R3_7", "r4_label": "R4_7", "r5_label": "R5_0"}


def synthesizable():
    with open(EXAMPLES / "redox_feasible_959.csv") as handle:
        return {tuple(row.values()) for row in csv.DictReader(handle)}


def test_redox_config_loads_with_descriptors_lookup_and_chimera():
    planner = Planner(str(EXAMPLES / "redox_flow_battery.yaml"), seed=0)
    assert planner.space.finite_size == 2 * 8 * 8 * 11
    assert [p.descriptors.shape for p in planner.space.parameters] == [(2, 4), (8, 7), (8, 7), (11, 7)]
    assert planner.feasible_fraction.method == "enumerated"
    assert round(planner.feasible_fraction.value * 1408) == 959
    assert [(o.name, o.tolerance, o.absolute) for o in planner.objectives] == [
        ("abs_lam_diff", 25.0, True), ("ered", 2.04, True), ("gsol", 0.0, False)]


def test_lookup_constraint_admits_exactly_the_959_synthesizable_candidates():
    planner = Planner(str(EXAMPLES / "redox_flow_battery.yaml"), seed=0)
    points = planner.space.enumerate()
    mask = planner.constraints.feasible(points)
    feasible = {tuple(p.values()) for p, ok in zip(planner.space.to_params(points), mask) if ok}
    assert feasible == synthesizable()


def test_chimera_picks_the_papers_best_candidate_among_all_synthesizable_ones():
    planner = Planner(str(EXAMPLES / "redox_flow_battery.yaml"), seed=0)
    emulator = RedoxEmulator()
    names = ("r1_label", "r3_label", "r4_label", "r5_label")
    rows = [dict(zip(names, key)) for key in synthesizable()]
    planner.tell([{**row, **emulator.measure(row)} for row in rows])
    assert planner.best().params == BEST_REDOX


def test_short_redox_run_proposes_only_synthesizable_candidates():
    planner = Planner(str(EXAMPLES / "redox_flow_battery.yaml"), seed=1)
    emulator, allowed = RedoxEmulator(noise=True, seed=1), synthesizable()
    for _ in range(6):
        (proposal,) = planner.ask()
        assert tuple(proposal.params.values()) in allowed
        planner.tell({**proposal.params, **emulator.measure(proposal.params), "experiment_id": proposal.experiment_id})
    assert planner.descriptor_summary()  # dynamic descriptors learned something to report


@pytest.mark.ros
def test_redox_campaign_over_ros(tmp_path):
    result = subprocess.run([sys.executable, "-m", "gryffin_ros.cli", "campaign", "--config",
                             str(EXAMPLES / "redox_flow_battery.yaml"), "--budget", "6", "--seed", "2", "--out",
                             str(tmp_path)], capture_output=True, text=True, timeout=300, env=ros_environment())
    assert result.returncode == 0, result.stdout + result.stderr
    rows = list(csv.DictReader(open(tmp_path / "experiments.csv")))
    assert len(rows) >= 6
    allowed = synthesizable()
    assert all((r["r1_label"], r["r3_label"], r["r4_label"], r["r5_label"]) in allowed for r in rows)
    assert {"abs_lam_diff (nm)", "ered (V)", "gsol (eV)", "failed", "strategy", "surrogate"} <= set(rows[0])


def test_several_seeds_write_a_summary(tmp_path):
    result = subprocess.run([sys.executable, "-m", "gryffin_ros.cli", "campaign", "--no-ros", "--budget", "5",
                             "--seeds", "2", "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    summary = (tmp_path / "summary.md").read_text()
    assert "| 0 | 5 |" in summary and "| 1 | 5 |" in summary
    assert (tmp_path / "seed-1" / "experiments.csv").exists()
