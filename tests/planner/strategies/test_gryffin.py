"""The public ask/tell API: config handling, observation validation, determinism, state, Gryffin compatibility."""

import json
import math

import numpy as np
import pytest
import yaml

from gryffin_ros.planner import (
    ConfigError,
    ConstraintError,
    ExhaustedSpaceError,
    Genetic,
    NoFeasiblePointError,
    ObservationError,
    Planner,
    Random,
)
from tests.conftest import branin, branin_feasible


def run(planner, n, objective=lambda p: p["x0"] + p["x1"], name="y", made=None):
    """n ask/tell rounds; the proposals are appended to `made` when given (tell refuses infeasible observations, so
    what the planner proposed is what a feasibility check must look at)."""
    for _ in range(n):
        for proposal in planner.ask():
            if made is not None:
                made.append(proposal)
            planner.tell({**proposal.params, name: objective(proposal.params),
                          "experiment_id": proposal.experiment_id})
    return planner


def test_config_from_yaml_and_json_files(tmp_path, unit_square_config):
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(unit_square_config))
    (tmp_path / "c.json").write_text(json.dumps(unit_square_config))
    for path in ("c.yaml", "c.json"):
        planner = Planner(str(tmp_path / path), seed=0)
        assert planner.space.names == ("x0", "x1")


@pytest.mark.parametrize("patch, message", [
    ({"optimiser": {}}, "unknown top-level config key(s) ['optimiser']"),
    ({"general": {"batch_size": 2}}, "unknown key 'general.batch_size'"),
    ({"general": {"batches": "2"}}, "'general.batches' has the wrong type"),
    ({"general": {"batches": 0}}, "'general.batches' must be at least 1"),
    ({"general": {"acquisition_optimizer": "lbfgs"}}, "'general.acquisition_optimizer' must be one of"),
    ({"general": {"feas_model": "svm"}}, "'general.feas_model' must be one of ['gp', 'kde'], got 'svm'"),
    ({"general": {"feasible_fraction": 1.5}}, "must be in (0, 1]"),
    ({"general": {"auto_desc_gen": "yes"}}, "'general.auto_desc_gen' has the wrong type"),
    ({"general": {"batches": True}}, "'general.batches' has the wrong type"),
    ({"objectives": [{"name": "y", "goal": "best"}]}, "'goal' must be 'min' or 'max'"),
    ({"objectives": [{"name": "x0"}]}, "same name as a parameter"),
    ({"objectives": [{"name": "a", "tolerance": 1.5}, {"name": "b"}]}, "relative 'tolerance' must be in [0, 1]"),
    ({"objectives": [{"name": "a", "absolute": "yes"}, {"name": "b"}]}, "'absolute' must be true or false"),
    ({"general": {"softness": -1.0}}, "'general.softness' must be a non-negative number"),
    ({"constraints": "x0 < 1"}, "'constraints' must be a list"),
    ({"constraints": ["x2 < 1"]}, "unknown name 'x2'"),
    ({"constraints": ["__import__('os')"]}, "not allowed"),
])
def test_config_errors_name_the_key(unit_square_config, patch, message):
    with pytest.raises(ConfigError) as info:
        Planner({**unit_square_config, **patch})
    assert message in str(info.value)


def test_config_file_errors_are_clear(tmp_path):
    with pytest.raises(ConfigError, match="cannot read config file"):
        Planner(str(tmp_path / "missing.yaml"))
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(ConfigError, match="not valid JSON"):
        Planner(str(tmp_path / "bad.json"))


def test_gryffin_no_op_general_keys_are_accepted(unit_square_config):
    Planner({**unit_square_config, "general": {"num_cpus": 4, "boosted": False, "verbosity": 3}})


def test_known_constraints_must_be_callables(unit_square_config):
    with pytest.raises(ConfigError, match="not a callable"):
        Planner(unit_square_config, known_constraints=["x0 < 1"])


@pytest.mark.parametrize("observation, message", [
    ({"x0": 0.5, "y": 1.0}, "missing parameter"),
    ({"x0": 0.5, "x1": 1.5, "y": 1.0}, "above its upper bound 1.0"),
    ({"x0": 0.5, "x1": 0.5, "y": 1.0, "z": 3}, "unknown key(s) ['z']"),
    ({"x0": 0.5, "x1": 0.5, "y": "high"}, "must be a number or null"),
    ({"x0": 0.5, "x1": 0.5, "y": math.inf}, "not finite"),
    ({"params": {"x0": 0.5, "x1": 0.5}, "objectives": {"q": 1.0}}, "unknown objective(s) ['q']"),
    ({"params": {"x0": 0.5, "x1": 0.5, "x9": 1}, "objectives": {"y": 1.0}}, "unknown parameter(s) ['x9']"),
    ({"params": {"x0": 0.9, "x1": 0.9}, "objectives": {"y": 1.0}}, "violate the known constraint(s) ['x0 + x1 <= 1']"),
])
def test_bad_observations_are_rejected_and_nothing_is_stored(unit_square_config, observation, message):
    planner = Planner({**unit_square_config, "constraints": ["x0 + x1 <= 1"]}, seed=0)
    planner.tell({"x0": 0.1, "x1": 0.1, "y": 0.0})
    with pytest.raises(ObservationError) as info:
        planner.tell([{"x0": 0.2, "x1": 0.2, "y": 1.0}, observation])
    assert message in str(info.value)
    assert len(planner.observations) == 1  # the valid first item of the batch was not stored either


def test_failed_experiments_are_stored_but_left_out_of_the_regression(unit_square_config):
    planner = Planner(unit_square_config, seed=0)
    planner.tell([{"x0": 0.1, "x1": 0.1, "y": None}, {"x0": 0.2, "x1": 0.2, "y": None},
                  {"x0": 0.3, "x1": 0.3, "y": 2.0}])
    assert [o.failed for o in planner.observations] == [True, True, False]
    assert planner.best().objectives == {"y": 2.0}
    assert len(planner.ask(2)) == 2


def test_nan_is_not_a_result_a_failure_is_said_with_none(unit_square_config):
    planner = Planner(unit_square_config, seed=0)
    with pytest.raises(ObservationError, match="report a failed experiment as None"):
        planner.tell({"x0": 0.2, "x1": 0.2, "y": float("nan")})
    assert not planner.observations


def test_duplicate_experiment_ids_are_rejected(unit_square_config):
    planner = Planner(unit_square_config, seed=0)
    (proposal,) = planner.ask()
    planner.tell({**proposal.params, "y": 1.0, "experiment_id": proposal.experiment_id})
    assert planner.pending == {}
    with pytest.raises(ObservationError, match="already reported"):
        planner.tell({**proposal.params, "y": 2.0, "experiment_id": proposal.experiment_id})


def test_same_seed_and_data_give_the_same_proposals(mixed_config):
    def campaign(seed):
        planner = Planner(mixed_config, seed=seed)
        for _ in range(6):
            for p in planner.ask(2):
                planner.tell({**p.params, "yield": p.params["T"] / 150 + p.params["n"],
                              "experiment_id": p.experiment_id})
        return [p.params for p in planner.ask(3)]
    assert campaign(7) == campaign(7)
    assert campaign(7) != campaign(8)


def test_a_planner_given_the_same_history_proposes_the_same(mixed_config):
    """A planner keeps no state of its own: another one given a copy of the history (what a campaign's store holds)
    draws the same proposals, pending ones avoided alike."""
    planner = Planner(mixed_config, seed=3)
    for p in planner.ask(4):
        planner.tell({**p.params, "yield": p.params["T"], "experiment_id": p.experiment_id})
    pending = planner.ask(2)
    restored = Planner(mixed_config, seed=3, history=planner.history.snapshot())
    assert set(restored.pending) == {p.experiment_id for p in pending} and restored.ask_count == 2
    assert [p.params for p in restored.ask(2)] == [p.params for p in planner.ask(2)]


def test_draw_leaves_the_history_as_it_was(mixed_config):
    planner = Planner(mixed_config, seed=3)
    for p in planner.ask(3):
        planner.tell({**p.params, "yield": p.params["T"], "experiment_id": p.experiment_id})
    drawn, ask_count, proposal_count = planner.draw(2)
    assert planner.pending == {} and planner.ask_count == 1 and ask_count == 2
    asked = planner.ask(2)
    assert [p.params for p in asked] == [p.params for p in drawn]  # the same draws, now recorded
    assert (planner.ask_count, planner.proposal_count) == (ask_count, proposal_count)
    assert set(planner.pending) == {p.experiment_id for p in asked}


def test_recommend_is_stateless_and_gryffin_shaped(unit_square_config):
    planner = Planner({**unit_square_config, "general": {"batches": 2, "sampling_strategies": 2}}, seed=1)
    observations = [{"x0": 0.1 * i, "x1": 0.05 * i, "y": float(i)} for i in range(1, 6)]
    first = planner.recommend(observations)
    assert len(first) == 4 and all(set(p) == {"x0", "x1"} for p in first)
    assert planner.observations == [] and planner.pending == {}
    assert planner.recommend(observations) == first


def test_alternating_strategies_and_batches(unit_square_config):
    planner = run(Planner(unit_square_config, seed=0), 3)
    assert [p.strategy for p in planner.ask(4)] == [1.0, -1.0, 1.0, -1.0]


def test_pending_proposals_are_not_proposed_again_in_a_finite_space():
    config = {"parameters": [{"name": "a", "type": "categorical", "options": ["p", "q", "r"]},
                             {"name": "b", "type": "discrete", "low": 0, "high": 1}],
              "objectives": [{"name": "y", "goal": "min"}]}
    planner = Planner(config, seed=0)
    planner.tell({"a": "p", "b": 0, "y": 1.0})
    seen = {("p", 0)}
    for _ in range(5):
        (proposal,) = planner.ask()
        key = (proposal.params["a"], proposal.params["b"])
        assert key not in seen
        seen.add(key)
    with pytest.raises(ExhaustedSpaceError, match="neither observed nor pending"):
        planner.ask()


def test_a_raising_constraint_reaches_the_caller_named(unit_square_config):
    def unsafe_mixture(params):
        raise KeyError("solvent")
    planner = Planner(unit_square_config, known_constraints=unsafe_mixture, seed=0)
    with pytest.raises(ConstraintError, match="'unsafe_mixture' raised KeyError"):
        planner.ask()


def test_infeasible_everywhere_is_a_clear_error_not_a_hang(unit_square_config):
    planner = Planner({**unit_square_config, "constraints": ["x0 < 0", "x1 < 0.5"],
                       "general": {"max_rejection_draws": 50_000}}, seed=0)
    with pytest.raises(NoFeasiblePointError):
        planner.ask()


def test_tiny_feasible_region_with_given_fraction_still_yields_feasible_proposals(unit_square_config):
    config = {**unit_square_config, "constraints": ["(x0 - 0.3) ** 2 + (x1 - 0.6) ** 2 < 0.03 ** 2"],
              "general": {"feasible_fraction": 0.0028, "num_random_samples": 20}}
    planner = run(Planner(config, seed=0), 4, objective=lambda p: p["x0"])
    for p in planner.ask(2):
        assert (p.params["x0"] - 0.3) ** 2 + (p.params["x1"] - 0.6) ** 2 < 0.03 ** 2


def test_maximization_goal_prefers_larger_values(unit_square_config):
    config = {**unit_square_config, "objectives": [{"name": "y", "goal": "max"}]}
    planner = Planner(config, seed=0)
    planner.tell([{"x0": 0.1, "x1": 0.1, "y": 1.0}, {"x0": 0.9, "x1": 0.9, "y": 5.0}])
    assert planner.best().params == {"x0": 0.9, "x1": 0.9}


@pytest.mark.parametrize("strategy", [Random, Genetic])
def test_baselines_share_the_interface_and_respect_constraints(strategy, unit_square_config):
    made = []
    planner = run(strategy({**unit_square_config, "constraints": ["x0 <= x1"]}, seed=0), 30, made=made)
    assert len(planner.observations) == 30 and len(made) == 30
    assert all(p.params["x0"] <= p.params["x1"] for p in made)
    again = type(planner)(planner.config, seed=0, history=planner.history.snapshot())
    assert [p.params for p in again.ask(2)] == [p.params for p in planner.ask(2)]


@pytest.mark.slow
def test_constrained_branin_beats_random_search(unit_square_config):
    """Paper constraint, 50 evaluations, 4 seeds: the planner's median best beats random search's."""
    def best_after(strategy, seed, budget=50):
        planner, made = strategy(unit_square_config, known_constraints=branin_feasible, seed=seed), []
        run(planner, budget, objective=lambda p: branin(p["x0"], p["x1"]), made=made)
        assert len(made) == budget and all(branin_feasible(p.params) for p in made)
        return planner.best().objectives["y"]
    ours = np.median([best_after(Planner, s) for s in range(4)])
    random = np.median([best_after(Random, s) for s in range(4)])
    assert ours < random
    assert ours < 1.0  # the constrained optimum is 0.3979; random search is at ~1.8 here


def test_a_report_missing_an_objective_is_refused_and_a_failure_says_so(unit_square_config):
    config = {**unit_square_config, "objectives": [{"name": "y", "goal": "min", "tolerance": 0.5},
                                                   {"name": "cost", "goal": "min"}]}
    planner = Planner(config, seed=0)
    (proposal,) = planner.ask()
    with pytest.raises(ObservationError, match=r"missing objective\(s\) \['cost'\]"):  # as over ROS
        planner.tell({**proposal.params, "y": 0.3, "experiment_id": proposal.experiment_id})
    assert planner.observations == [] and planner.best() is None
    planner.tell({**proposal.params, "y": None, "cost": None, "experiment_id": proposal.experiment_id})  # failed
    assert planner.observations[0].failed
    (proposal,) = planner.ask()
    planner.tell({**proposal.params, "y": 0.3, "cost": 2.0, "experiment_id": proposal.experiment_id})
    assert planner.best().objectives == {"y": 0.3, "cost": 2.0}


def test_a_candidate_a_fraction_of_a_degree_from_an_observation_is_the_same_experiment():
    """0.02 degC of a 50 degC range from an observed point, same solvent: not a new experiment, whatever its
    acquisition says; another solvent at the same temperature is."""
    from gryffin_ros.planner.strategies.selection import DUPLICATE_DISTANCE, select
    space = Planner({"parameters": [{"name": "T", "type": "continuous", "low": 50.0, "high": 100.0},
                                    {"name": "solvent", "type": "categorical", "options": ["a", "b", "c"]}],
                     "objectives": [{"name": "y", "goal": "max"}]}, seed=0).space
    observed = space.to_internal([{"T": 80.0, "solvent": "b"}])
    near, other_solvent, far = space.to_internal([{"T": 80.02, "solvent": "b"}, {"T": 80.0, "solvent": "c"},
                                                  {"T": 60.0, "solvent": "b"}])
    assert 0.02 / 50.0 < DUPLICATE_DISTANCE < 1.0  # a different option is never within it
    for diverse in (False, True):
        assert select(space, np.array([near, far]), np.array([-10.0, 0.0]), observed, observed[:0], diverse) == 1
        assert select(space, np.array([near, other_solvent]), np.array([-10.0, 0.0]), observed, observed[:0],
                      diverse) == 1


def test_an_observation_is_converted_to_the_planners_coordinates_once_when_it_is_accepted(monkeypatch):
    """tell() validates and converts each observation once; the models read that row (no second conversion), and
    observations that come without it (read back from a store) are converted when first needed."""
    from gryffin_ros.planner import Observation
    config = {"parameters": [{"name": "T", "type": "continuous", "low": 50.0, "high": 100.0},
                             {"name": "solvent", "type": "categorical", "options": ["a", "b"]}],
              "objectives": [{"name": "y", "goal": "max"}]}
    planner = Planner(config, seed=0)
    planner.tell([{"T": 60.0, "solvent": "b", "y": 1.0}, {"T": 75.0, "solvent": "a", "y": 2.0}])
    stored = Observation({"T": 100.0, "solvent": "a"}, {"y": 0.5}, "from-a-store")
    planner.history.add_observations([stored])
    converted = []
    real = type(planner.space).to_internal
    monkeypatch.setattr(type(planner.space), "to_internal",
                        lambda self, rows: converted.append(len(rows)) or real(self, rows))
    assert planner.observed_points() == pytest.approx(np.array([[0.2, 1.0], [0.5, 0.0], [1.0, 0.0]]))
    assert converted == [1]  # only the stored one


def test_a_gp_runs_each_option_of_a_small_categorical_twice_before_it_settles():
    """The GP's expected improvement alone can leave options untried for a whole campaign; each option of a small
    categorical parameter is run twice first (those the known constraints rule out never), the continuous
    condition optimized under it, and the proposals say so. A 12-option parameter is left to its descriptors."""
    solvents = {name: [float(i), float(i % 3)] for i, name in enumerate("ABCDEF")}
    config = {"parameters": [{"name": "solvent", "type": "categorical", "descriptors": solvents},
                             {"name": "T", "type": "continuous", "low": 0.0, "high": 1.0}],
              "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"},
              "constraints": ["solvent != 'F'"]}

    def measure(p):  # A is best; the others get worse along the first descriptor
        return "ABCDEF".index(p["solvent"]) + (p["T"] - 0.3) ** 2

    planner = Planner(config, seed=0)
    start = [{"solvent": s, "T": t} for s, t in (("A", 0.1), ("A", 0.8), ("B", 0.5), ("B", 0.2), ("A", 0.5))]
    planner.tell([{**p, "y": measure(p)} for p in start])
    runs = {s: 0 for s in "ABCDEF"}
    for p in start:
        runs[p["solvent"]] += 1
    for _ in range(6):
        (proposal,) = planner.ask()
        solvent = proposal.params["solvent"]
        runs[solvent] += 1
        assert f"solvent={solvent}" in proposal.meta["covering"]
        planner.tell({**proposal.params, "y": measure(proposal.params), "experiment_id": proposal.experiment_id})
    assert runs == {"A": 3, "B": 2, "C": 2, "D": 2, "E": 2, "F": 0}  # 6 asks: C, D and E twice each
    (proposal,) = planner.ask()  # every option run twice: the expected improvement alone again
    assert "covering" not in proposal.meta

    many = {**config, "parameters": [{"name": "solvent", "type": "categorical",
                                      "descriptors": {f"S{i}": [float(i), float(i % 3)] for i in range(12)}},
                                     config["parameters"][1]], "constraints": []}
    planner = Planner(many, seed=0)
    planner.tell([{"solvent": "S0", "T": t, "y": (t - 0.3) ** 2} for t in (0.1, 0.5, 0.8)]
                 + [{"solvent": "S1", "T": t, "y": 1 + (t - 0.3) ** 2} for t in (0.2, 0.6)])
    (proposal,) = planner.ask()
    assert "covering" not in proposal.meta
