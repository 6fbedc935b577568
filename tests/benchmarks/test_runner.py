"""The benchmark runner: the paper's protocol on a few seeds, zero violations, resumable, summaries, the CLI."""

import json

import pytest

from benchmarks import runner
from benchmarks.bench import main
from benchmarks.runner import Job, best_so_far, run_job, run_jobs, summarize
from benchmarks.surfaces import SURFACES


def test_discrete_run_stops_at_the_optimum_without_violations():
    record = run_job(Job("sphere", "adam", seed=1, budget=441))
    assert record["violations"] == 0 and record["error"] is None
    found = record["evaluations_to_optimum"]
    assert found == len(record["values"]) and record["points"][-1] == [10, 10]
    assert record["values"][-1] == 0.0 and min(record["values"][:-1]) > 0.0
    assert found < 100  # random search needs ~160 on average


@pytest.mark.parametrize("strategy", ["genetic", "random", "deap"])
def test_every_strategy_respects_the_constraint(strategy):
    record = run_job(Job("branin", strategy, seed=2, budget=25))
    surface = SURFACES["branin"]
    assert record["violations"] == 0 and len(record["values"]) == 25
    assert all(surface.is_feasible({"x0": a, "x1": b}) for a, b in record["points"])


def test_same_seed_same_run():
    first, second = (run_job(Job("dejong", "adam", seed=5, budget=12)) for _ in range(2))
    assert first["points"] == second["points"] and first["values"] == second["values"]


def test_runs_are_stored_and_resumed(tmp_path, monkeypatch):
    jobs = [Job("slope", "adam", seed, 441) for seed in range(2)]
    done = []
    records = run_jobs(jobs, tmp_path, processes=1, progress=lambda job, record: done.append(job.seed))
    assert done == [0, 1] and all(job.path(tmp_path).exists() for job in jobs)

    def refuse(job):
        raise AssertionError(f"{job} was run again")
    monkeypatch.setattr(runner, "run_job", refuse)
    again = run_jobs(jobs + [], tmp_path, processes=1, progress=lambda job, record: done.append(job.seed))
    assert done == [0, 1] and again == records


def test_summary_of_discrete_and_continuous_runs():
    assert best_so_far([3.0, 5.0, 1.0], 5) == [3.0, 3.0, 1.0, 1.0, 1.0]
    discrete = [{"surface": "slope", "budget": 441, "values": [2.0, 0.0], "violations": 0,
                 "evaluations_to_optimum": n, "median_ask_seconds": 0.01} for n in (2, 4, 9)]
    summary = summarize(discrete)
    assert summary["evaluations_mean"] == pytest.approx(5.0) and summary["evaluations_median"] == 4
    assert summary["found"] == 3 and summary["violations"] == 0
    values = [5.0] * 9 + [1.0] * 91
    continuous = summarize([{"surface": "dejong", "budget": 100, "values": values, "violations": 0,
                             "evaluations_to_optimum": None, "median_ask_seconds": 0.01}])
    assert continuous["best_at_10"] == 1.0 and continuous["best_at_100"] == 1.0
    assert continuous["regret_at_10"] == pytest.approx(0.0, abs=1e-6)


def test_bench_command_runs_in_parallel_and_writes_summaries(tmp_path, capsys):
    out, summaries = tmp_path / "runs", tmp_path / "summary.json"
    code = main(["--surface", "slope", "--strategy", "adam,random", "--seeds", "2", "--processes", "2",
                 "--out", str(out), "--json", str(summaries)])
    assert code == 0
    data = json.loads(summaries.read_text())
    assert set(data) == {"slope/adam", "slope/random"}
    assert data["slope/adam"]["runs"] == 2 and data["slope/adam"]["violations"] == 0
    assert len(list((out / "slope" / "adam" / "budget441").glob("seed*.json"))) == 2
    assert "evaluations to optimum" in capsys.readouterr().out


def test_bench_command_rejects_unknown_names(capsys):
    assert main(["--surface", "rosenbrock"]) == 2
    assert "rosenbrock" in capsys.readouterr().err
