"""benchmarks.trace: one campaign of a portfolio task, experiment by experiment (benchmarks/trace.py)."""

import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks import from_scratch, portfolio_tasks, trace

ROOT = Path(__file__).resolve().parents[2]


def test_a_point_is_described_by_its_option_names_and_conditions():
    task = portfolio_tasks.TASKS["m_oxidation"]()
    x = [task.coppers.index("CuOTf"), task.nitroxyls.index("ABNO"), 1,
         portfolio_tasks.OX_ATMOSPHERES.index("air"), 45.0, 7.6, 9.0]
    assert trace.describe(task, x) == "copper=CuOTf nitroxyl=ABNO bpy=1 atmosphere=air T=45 t=7.6 loading=9"


def test_the_harness_start_tells_the_task_s_initial_points_first_then_prints_the_planner_s_proposals():
    task = portfolio_tasks.TASKS["m_oxidation"]()
    initial = task.initial_points(2)
    out = list(trace.lines(task, 2, budget=len(initial) + 1))
    assert len(out) == len(initial) + 2
    for k, (line, x) in enumerate(zip(out, initial), 1):
        assert line.split()[:2] == [str(k), "initial"]
        assert trace.describe(task, x) in line
    proposal = out[len(initial)].split()
    assert proposal[0] == str(len(initial) + 1) and proposal[1] != "initial"
    results = [float(line.split("  ")[-1]) for line in out[:len(initial)]]
    best = float(out[-1].split(",")[0].split()[1])
    assert best <= min(results)  # the summary's best is at least as good as every initial result
    regret = float(out[-1].split("regret")[1])
    # both printed to 4 decimals: each off by at most 5e-5
    assert regret == pytest.approx(best - from_scratch.REFERENCES["m_oxidation"], abs=1e-4)


def test_hidden_failures_are_refused_for_a_task_without_them_and_an_unknown_task_is_named():
    command = [sys.executable, "-m", "benchmarks.trace"]
    hidden = subprocess.run(command + ["--task", "m_photoredox", "--hidden"], cwd=ROOT, capture_output=True,
                            text=True)
    assert hidden.returncode != 0 and "--hidden is defined for" in hidden.stderr
    unknown = subprocess.run(command + ["--task", "m_nothing"], cwd=ROOT, capture_output=True, text=True)
    assert unknown.returncode != 0 and "m_nothing" in unknown.stderr


def test_a_campaign_from_scratch_starts_with_the_planner_s_first_proposal():
    budget = 3
    task = portfolio_tasks.TASKS["m_oxidation"]()
    out = list(trace.lines(task, 0, scratch=True, hidden=True, budget=budget))
    assert len(out) == budget + 1
    for k, line in enumerate(out[:-1], 1):
        assert line.split()[0] == str(k) and line.split()[1] != "initial"
    assert out[-1].startswith("best ")


def test_the_gp_after_k_experiments_names_each_input_s_length_scale_and_scores_the_best_result_and_changes():
    """--gp-after: the GP the campaign's next ask builds, each Matern term's length scales by input name (m_oxidation:
    three conditions, two descriptor columns of each salt and nitroxyl, the bipyridine level; the atmosphere, without
    descriptors, in the categorical kernel), then the best result and an --at point (the best result with bipyridine
    changed), each with its true result."""
    task = portfolio_tasks.TASKS["m_oxidation"]()
    after = len(task.initial_points(2)) + 3
    out = list(trace.gp_lines(task, 2, after, at=["bpy=1"]))
    assert out[0].startswith(f"GP after {after} experiments")
    terms = [line for line in out if line.strip().startswith("Matern term")]
    assert terms
    inputs = ["T", "t", "loading", "copper[0]", "copper[1]", "nitroxyl[0]", "nitroxyl[1]", "bpy"]
    for line in terms:
        pairs = line.split(": ", 1)[1].split(", ")
        assert [p.rsplit(" ", 1)[0] for p in pairs] == inputs
        assert all(1e-3 * (1 - 1e-6) <= float(p.rsplit(" ", 1)[1]) <= 20 * (1 + 1e-3) for p in pairs)
    assert any("categorical kernel" in line and "atmosphere" in line for line in out)
    best, changed = out[-2], out[-1]
    assert best.startswith("best result: ") and changed.startswith("bpy=1: ")
    results = [y for _, _, y, _, _ in from_scratch.steps(task, 2, after, lambda *_: False, task.initial_points(2))]
    # printed to 4 decimals
    assert float(best.rsplit("true result ", 1)[1]) == pytest.approx(min(results), abs=1e-4)
    best_point, changed_point = (line.split(": ")[1].split() for line in (best, changed))
    assert [p for p in changed_point if not p.startswith("bpy=")] == [p for p in best_point if not p.startswith("bpy=")]
    assert "bpy=1" in changed_point
    for line in (best, changed):
        assert float(line.split("+- ")[1].split()[0]) > 0  # a posterior standard deviation


def test_an_at_point_naming_an_unknown_parameter_or_option_is_refused_with_the_known_ones():
    task = portfolio_tasks.TASKS["m_oxidation"]()
    after = len(task.initial_points(0)) + 1
    with pytest.raises(ValueError, match="unknown parameter 'bipy'.*bpy"):
        list(trace.gp_lines(task, 0, after, at=["bipy=1"]))
    with pytest.raises(ValueError, match="copper has no option 'CuCl'.*CuOTf"):
        list(trace.gp_lines(task, 0, after, at=["copper=CuCl"]))
    with pytest.raises(ValueError, match="bpy takes an integer, not 'one'"):
        list(trace.gp_lines(task, 0, after, at=["bpy=one"]))


def test_an_at_point_that_the_hidden_failures_fail_says_so_instead_of_a_result():
    """m_oxidation's hidden failures fail every experiment with AZADO: with --hidden, such a point's true result is
    a failure, not the objective's value."""
    task = portfolio_tasks.TASKS["m_oxidation"]()
    out = list(trace.gp_lines(task, 0, 8, at=["nitroxyl=AZADO", "nitroxyl=ABNO"], scratch=True, hidden=True))
    azado, abno = out[-2], out[-1]
    assert azado.startswith("nitroxyl=AZADO: ") and azado.endswith("true result failed (hidden)")
    assert abno.startswith("nitroxyl=ABNO: ") and "failed" not in abno
