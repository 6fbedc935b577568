"""The lab-scale timing benchmark's two versions of its 10-D problem (benchmarks/lab_scale.py): with the known
constraints, whose optimum lies on one of them, and without (`warm_free`)."""

import numpy as np

from benchmarks import lab_scale


def test_the_free_problem_has_no_known_constraints_and_its_points_cover_the_cube():
    assert len(lab_scale.problem(10, None)["constraints"]) == 2
    assert lab_scale.problem(10, None, constrained=False)["constraints"] == []
    constrained = lab_scale.feasible_points(400, 10, np.random.default_rng(0))
    free = lab_scale.feasible_points(400, 10, np.random.default_rng(0), constrained=False)
    assert constrained.shape == free.shape == (400, 10)
    assert (constrained.sum(axis=1) <= 6.0).all()
    assert (free.sum(axis=1) > 6.0).any()  # sums of 10 uniforms: about 14 % above 6


def test_a_planner_without_constraints_answers_a_warm_ask():
    planner, _ = lab_scale.planner_with(30, 3, "kde", seed=0, constrained=False)
    (proposal,) = planner.ask(1)
    lab_scale.tell_result(planner, proposal)
    assert len(planner.observations) == 31
