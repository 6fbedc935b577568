"""The Gryffin 1.0 drop-in class (gryffin_ros.compat.Gryffin) and Gryffin 1.0's configuration keys.

Gryffin 1.0's own test suite runs against the same class from ../shared/compat/gryffin1/run.sh; these tests check
what it does not: every documented key, argument semantics, the read-outs and the Gryffin script of docs/gryffin1.md.
"""

import json
import logging
import math
import re
from pathlib import Path

import numpy as np
import pytest

from gryffin_ros.compat import Gryffin, UnsupportedError
from gryffin_ros.planner import ConfigError, GryffinRosError, ObservationError, Planner, load_config
from gryffin_ros.planner.notices import forget_notices
from gryffin_ros.planner.strategies.selection import diversity

ROOT = Path(__file__).resolve().parents[1]


def gryffin_default_configuration():
    """Gryffin 1.0's documented default configuration (utilities/defaults.py, get_config_defaults()), every key of
    its general, database and model sections with Gryffin's default values."""
    return {
        "general": {
            "num_cpus": 1, "boosted": True, "caching": True, "auto_desc_gen": False, "batches": 1,
            "sampling_strategies": 2, "softness": 0.001, "feas_approach": "fwa", "feas_param": 1, "dist_param": 0.5,
            "random_seed": None, "save_database": False, "acquisition_optimizer": "adam", "obj_transform": "sqrt",
            "num_random_samples": 200, "reject_tol": 1000, "verbosity": 4,
        },
        "database": {"format": "sqlite", "path": "./SearchProgress", "log_observations": True, "log_runtimes": True},
        "model": {"num_epochs": 2000, "learning_rate": 0.05, "num_draws": 1000, "num_layers": 3, "hidden_shape": 6,
                  "weight_loc": 0.0, "weight_scale": 1.0, "bias_loc": 0.0, "bias_scale": 1.0},
        "parameters": [{"name": "param_0", "type": "continuous", "low": 0, "high": 1},
                       {"name": "param_1", "type": "continuous", "low": 0, "high": 1}],
        "objectives": [{"name": "obj_0", "goal": "min", "tolerance": 0.2, "absolute": False},
                       {"name": "obj_1", "goal": "max", "tolerance": 0.2, "absolute": False}],
    }


@pytest.fixture
def square():
    return {"general": {"random_seed": 11},
            "parameters": [{"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                           {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}],
            "objectives": [{"name": "y", "goal": "min"}]}


def grid_observations(objective=lambda x0, x1: (x0 - 0.3) ** 2 + (x1 - 0.6) ** 2):
    points = [(0.1, 0.1), (0.3, 0.6), (0.8, 0.2), (0.6, 0.9), (0.5, 0.4), (0.9, 0.7)]
    return [{"x0": a, "x1": b, "y": objective(a, b)} for a, b in points]


# ---- configuration ---------------------------------------------------------------------------------------------------
def test_gryffin_default_configuration_loads_unchanged_with_its_effects():
    config = load_config(gryffin_default_configuration())
    general = config.general
    assert (general.batches, general.sampling_strategies, general.num_random_samples) == (1, 2, 200)
    assert (general.feas_approach, general.acquisition_optimizer, general.obj_transform) == ("fwa", "adam", "sqrt")
    assert general.dist_param == 0.5 and general.random_seed is None and general.auto_desc_gen is False
    assert [o.goal for o in config.objectives] == ["min", "max"]
    gryffin = Gryffin(config_dict=gryffin_default_configuration(), silent=True)
    assert gryffin.frac_feas == 1.0
    assert len(gryffin.recommend([])) == 2


def test_config_file_from_gryffin_docs_as_json(tmp_path):
    (tmp_path / "config.json").write_text(json.dumps(gryffin_default_configuration()))
    gryffin = Gryffin(config_file=str(tmp_path / "config.json"))
    assert gryffin.config.space.names == ("param_0", "param_1")


def test_keys_without_effect_are_logged_once(caplog):
    forget_notices()
    with caplog.at_level(logging.INFO, logger="gryffin_ros.config"):
        load_config(gryffin_default_configuration())
        load_config(gryffin_default_configuration())
    notes = [r.getMessage() for r in caplog.records if "has no effect here" in r.getMessage()]
    expected = {f"general.{k}" for k in ("num_cpus", "boosted", "caching", "save_database", "verbosity",
                                         "reject_tol")}
    expected |= {f"database.{k}" for k in gryffin_default_configuration()["database"]}
    expected |= {f"model.{k}" for k in gryffin_default_configuration()["model"]}
    logged = [re.match(r"'([^']+)'", n).group(1) for n in notes]
    assert sorted(logged) == sorted(expected)  # each once, although loaded twice
    assert not any(k in " ".join(notes) for k in ("general.batches", "dist_param", "obj_transform"))


def test_a_database_asked_for_is_a_warning(caplog):
    forget_notices()
    with caplog.at_level(logging.INFO, logger="gryffin_ros.config"):
        load_config({**gryffin_default_configuration(), "general": {"save_database": True}})
    (record,) = [r for r in caplog.records if "general.save_database" in r.getMessage()]
    assert record.levelno == logging.WARNING and "gryffin-ros export" in record.getMessage()


@pytest.mark.parametrize("patch, message", [
    ({"general": {"dist_parm": 0.5}}, "unknown key 'general.dist_parm'"),
    ({"database": {"formats": "sqlite"}}, "unknown key(s) ['database.formats']"),
    ({"model": {"num_epoch": 10}}, "unknown key(s) ['model.num_epoch']"),
    ({"model": [1]}, "'model' must be a mapping"),
    ({"modell": {}}, "unknown top-level config key(s) ['modell']"),
    ({"general": {"obj_transform": "log"}}, "'general.obj_transform' must be one of"),
    ({"general": {"dist_param": -1}}, "'general.dist_param' must be a non-negative number"),
])
def test_unknown_keys_and_bad_values_stay_errors(square, patch, message):
    with pytest.raises(ConfigError) as info:
        load_config({**square, **patch})
    assert message in str(info.value)


def test_the_drop_in_keeps_gryffins_model_and_still_refuses_a_general_that_is_no_mapping(square):
    """Gryffin's kernel density unless the config names a surrogate; setting that default must not swallow a
    malformed `general` (it did once: `general: 5` was replaced instead of refused)."""
    assert Gryffin(config_dict=square).config.general.surrogate == "kde"
    assert Gryffin(config_dict={**square, "general": {"surrogate": "gp"}}).config.general.surrogate == "gp"
    with pytest.raises(ConfigError, match="'general' must be a mapping"):
        Gryffin(config_dict={**square, "general": 5})


@pytest.mark.parametrize("transform, expected", [
    (None, lambda f: f), ("identity", lambda f: f), ("sqrt", np.sqrt), ("cbrt", np.cbrt), ("square", np.square),
])
def test_obj_transform_values_of_gryffin(square, transform, expected):
    planner = Planner({**square, "general": {"obj_transform": transform}}, seed=0)
    planner.tell([{"x0": 0.1 * i, "x1": 0.1, "y": float(i)} for i in range(5)])
    f = np.linspace(0.0, 1.0, 5)
    assert np.allclose(planner.merits(planner.observations), expected(f))
    assert np.allclose(planner.merits(planner.observations, transform=False), f)


def test_dist_param_sets_the_characteristic_distance(square):
    config = load_config({**square, "general": {"dist_param": 1.0}})
    assert config.general.dist_param == 1.0
    space = config.space
    candidate, reference = np.array([[0.8, 0.5]]), np.array([[0.5, 0.5]])  # 0.3 apart in x0, 0 in x1
    # n = 4: characteristic distance 1/sqrt(4) = 0.5 (Gryffin's default 0.5) or 1/4 (dist_param 1)
    assert diversity(space, candidate, reference, 4)[0] == pytest.approx(0.5 * (math.exp(-0.4) + math.exp(-1.0)))
    assert diversity(space, candidate, reference, 4, dist_param=1.0)[0] == pytest.approx(
        0.5 * (math.exp(0.1) + math.exp(-0.5)))


def test_parameter_size_loads(caplog):
    forget_notices()
    base = {"name": "x", "type": "continuous", "low": 0.0, "high": 10.0}
    assert load_config({"parameters": [{**base, "size": 1}]}).space.dim == 1
    with caplog.at_level(logging.INFO, logger="gryffin_ros.config"):
        space = load_config({"parameters": [{**base, "size": 2}, {"name": "c", "type": "categorical",
                                                                     "options": ["a", "b"], "size": 1}]}).space
    assert space.names == ("x", "c")  # one dimension each, as in Gryffin 1.0
    (record,) = [r for r in caplog.records if "parameters.x.size" in r.getMessage()]
    assert record.levelno == logging.WARNING and "has no effect here" in record.getMessage()
    for bad in (0, "2", 1.5, True):
        with pytest.raises(ConfigError, match="'size' must be a positive integer"):
            load_config({"parameters": [{**base, "size": bad}]})


def test_process_constrained_is_accepted_with_a_warning(caplog):
    forget_notices()
    with caplog.at_level(logging.INFO, logger="gryffin_ros.config"):
        load_config({"parameters": [{"name": "T", "type": "continuous", "low": 0, "high": 1,
                                     "process_constrained": True},
                                    {"name": "u", "type": "continuous", "low": 0, "high": 1,
                                     "process_constrained": False}]})
    messages = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert any("parameters.T.process_constrained" in m for m in messages)
    assert not any("parameters.u" in m for m in messages)


# ---- constructor and recommend -----------------------------------------------------------------------------------
def test_config_dict_wins_over_config_file(tmp_path, square, caplog):
    other = {**square, "parameters": [{"name": "z", "type": "continuous", "low": 0, "high": 1}]}
    (tmp_path / "c.json").write_text(json.dumps(other))
    with caplog.at_level(logging.WARNING, logger="gryffin_ros.compat"):
        gryffin = Gryffin(config_file=str(tmp_path / "c.json"), config_dict=square)
    assert gryffin.config.space.names == ("x0", "x1")
    assert any("config_dict is used" in r.getMessage() for r in caplog.records)
    with pytest.raises(ConfigError, match="config_file or a config_dict"):
        Gryffin()


def test_frac_feas_estimated_given_or_one(square):
    def below_diagonal(p):
        return p["x0"] + p["x1"] < 1.0

    assert Gryffin(config_dict=square, known_constraints=below_diagonal).frac_feas == pytest.approx(0.5, abs=0.02)
    assert Gryffin(config_dict=square, known_constraints=below_diagonal, frac_feas=0.3).frac_feas == 0.3
    assert Gryffin(config_dict=square, frac_feas=0.3).frac_feas == 1.0  # Gryffin ignores it without constraints
    with pytest.raises(ConfigError, match="feasible_fraction"):
        Gryffin(config_dict=square, known_constraints=below_diagonal, frac_feas=1.5)


def test_explicit_strategies_and_batches_are_honoured(square):
    observations = grid_observations()
    gryffin = Gryffin(config_dict=square)
    assert len(gryffin.recommend(observations)) == 2  # config: 1 batch x 2 strategies
    assert len(gryffin.recommend(observations, sampling_strategies=[1.0, 0.0, -1.0], num_batches=2)) == 6
    assert len(gryffin.recommend(observations, num_batches=3)) == 6
    best = np.array([0.3, 0.6])
    observed = np.array([[o["x0"], o["x1"]] for o in observations])

    def nearest(sample):
        return np.linalg.norm(observed - [sample["x0"], sample["x1"]], axis=1).min()

    exploit = gryffin.recommend(observations, sampling_strategies=[1], num_batches=3)
    explore = gryffin.recommend(observations, sampling_strategies=[-1], num_batches=3)
    assert len(exploit) == len(explore) == 3
    assert all(np.linalg.norm(best - [s["x0"], s["x1"]]) < 0.2 for s in exploit)
    assert min(nearest(s) for s in explore) > max(nearest(s) for s in exploit)
    assert list(gryffin.sampling_strategies) == [-1.0] and gryffin.num_batches == 3
    with pytest.raises(ValueError, match="sampling_strategies"):
        gryffin.recommend(observations, sampling_strategies=[])
    with pytest.raises(ValueError, match="num_batches"):
        gryffin.recommend(observations, num_batches=0)


def test_planner_recommend_arguments(square):
    planner = Planner(square, seed=4)
    observations = grid_observations()
    default = planner.recommend(observations)
    assert planner.recommend(observations) == default  # stateless
    assert planner.recommend(observations, sampling_strategies=[1.0, -1.0], num_batches=1) == default
    assert planner.recommend(observations, draw=1) != default
    assert planner.observations == [] and planner.pending == {}
    with pytest.raises(ValueError, match="sampling_strategies"):
        planner.recommend(observations, sampling_strategies=[float("nan")])
    with pytest.raises(ValueError, match="draw"):
        planner.recommend(observations, draw=-1)


def test_calls_draw_anew_and_replay_with_the_same_seed(square):
    first, second = Gryffin(config_dict=square), Gryffin(config_dict=square)
    a = [first.recommend([]) for _ in range(3)]
    b = [second.recommend([]) for _ in range(3)]
    assert a == b  # same seed, same sequence of calls
    assert a[0] != a[1] != a[2]  # each call draws anew, as Gryffin's NumPy state advances
    assert first.iter_counter == 3


def test_observations_in_gryffin_form(square):
    gryffin = Gryffin(config_dict=square)
    observations = [{**o, "note": "ignored, as in Gryffin", "iteration": i} for i, o in enumerate(grid_observations())]
    observations.append({"x0": 0.2, "x1": 0.2, "y": float("nan")})  # a failed experiment
    samples = gryffin.recommend(observations)
    assert all(set(s) == {"x0", "x1"} for s in samples)
    with pytest.raises(ObservationError, match="missing objective"):
        gryffin.recommend([{"x0": 0.2, "x1": 0.3}])
    with pytest.raises(ObservationError, match="above its upper bound"):
        gryffin.recommend([{"x0": 1.2, "x1": 0.3, "y": 1.0}])


def test_as_array_is_gryffins_vector_form():
    config = {"general": {"random_seed": 3, "batches": 2},
              "parameters": [{"name": "T", "type": "continuous", "low": 10.0, "high": 20.0},
                             {"name": "n", "type": "discrete", "low": 2, "high": 6},
                             {"name": "s", "type": "categorical", "category_details": {"a": None, "b": None,
                                                                                       "c": None}}],
              "objectives": [{"name": "y", "goal": "max"}]}
    first, second = Gryffin(config_dict=config), Gryffin(config_dict=config)
    samples, X = first.recommend([]), second.recommend([], as_array=True)
    assert X.shape == (4, 3)
    for sample, row in zip(samples, X):
        assert row[0] == pytest.approx(sample["T"]) and 10.0 <= row[0] <= 20.0
        assert row[1] == sample["n"] - 2
        assert row[2] == ["a", "b", "c"].index(sample["s"])


def test_an_olympus_style_gryffin_config_and_observations():
    """Olympus writes Gryffin configs with `size`, a discrete `stride` and descriptor-less category_details, and
    reports each objective as a 0-d array."""
    config = {"general": {"num_cpus": 4, "auto_desc_gen": False, "batches": 1, "sampling_strategies": 1,
                          "boosted": False, "caching": True, "random_seed": 5, "acquisition_optimizer": "adam",
                          "verbosity": 4},
              "parameters": [{"name": "c", "type": "continuous", "size": 1, "low": 0.0, "high": 1.0},
                             {"name": "d", "type": "discrete", "size": 1, "low": 0, "high": 10, "stride": 2},
                             {"name": "k", "type": "categorical", "size": 1,
                              "category_details": {"a": None, "b": None, "c": None}}],
              "objectives": [{"name": "obj", "goal": "min"}]}
    gryffin = Gryffin(config_dict=config)
    assert gryffin.config.space.parameters[1].options == (0, 2, 4, 6, 8, 10)
    observations = []
    for i in range(3):
        (sample,) = gryffin.recommend(observations, sampling_strategies=[[-1, 1][i % 2]])
        assert sample["d"] in (0, 2, 4, 6, 8, 10)
        observations.append({**sample, "obj": np.squeeze(np.array([sample["c"] + sample["d"]]))})
    assert len(observations) == 3
    with pytest.raises(ConfigError, match="stride"):
        Gryffin(config_dict={**config, "parameters": [{"name": "d", "type": "discrete", "low": 0, "high": 4,
                                                       "stride": 0}]})


def test_category_details_in_gryffins_forms(tmp_path):
    def config(details):
        return {"parameters": [{"name": "s", "type": "categorical", "category_details": details}],
                "objectives": [{"name": "y", "goal": "min"}]}

    empty = Gryffin(config_dict=config({"a": [], "b": [], "c": []}))
    assert empty.config.space.parameters[0].descriptors is None
    partial = Gryffin(config_dict=config({"a": [1.0], "b": None, "c": [2.0]}))  # any None: no descriptors (Gryffin)
    assert partial.config.space.parameters[0].descriptors is None
    (tmp_path / "cats.json").write_text(json.dumps({"a": [1.0, 5.0], "b": [2.0, 3.0], "c": [4.0, 4.0]}))
    (tmp_path / "cats.csv").write_text("a,1,5\nb,2,3\nc,4,4\n")
    for name in ("cats.json", "cats.csv"):
        table = Gryffin(config_dict=config(str(tmp_path / name))).config.space.parameters[0].descriptors
        assert table.shape == (3, 2) and np.allclose(table[:, 0], [0.0, 1 / 3, 1.0])
    with pytest.raises(ConfigError, match="only .json and .csv"):
        Gryffin(config_dict=config(str(tmp_path / "cats.pkl")))


# ---- read-outs -------------------------------------------------------------------------------------------------------
def test_read_outs_need_a_model(square):
    gryffin = Gryffin(config_dict=square)
    gryffin.recommend([])
    with pytest.raises(GryffinRosError, match="no model yet"):
        gryffin.get_regression_surrogate([{"x0": 0.5, "x1": 0.5}])
    with pytest.raises(UnsupportedError, match="gryffin-ros export"):
        gryffin.read_db()


@pytest.mark.parametrize("goal", ["min", "max"])
def test_regression_surrogate_in_objective_units(square, goal):
    config = {**square, "objectives": [{"name": "y", "goal": goal}]}
    observations = grid_observations(lambda a, b: 100.0 + 50.0 * a)
    gryffin = Gryffin(config_dict=config)
    gryffin.build_surrogate(observations)
    predicted = gryffin.get_regression_surrogate(observations)
    observed = np.array([o["y"] for o in observations])
    assert predicted.shape == (6,)
    assert np.all(np.abs(predicted - observed) < 0.25 * np.ptp(observed))
    assert np.argmin(predicted) == np.argmin(observed) and np.argmax(predicted) == np.argmax(observed)


def test_feasibility_density_acquisition_read_outs(square):
    observations = grid_observations()
    gryffin = Gryffin(config_dict=square)
    gryffin.recommend(observations, sampling_strategies=[1, -1])
    assert np.all(gryffin.get_feasibility_surrogate(observations) == 1.0)  # nothing failed yet
    failed = observations + [{"x0": 0.95, "x1": 0.05, "y": None}, {"x0": 0.9, "x1": 0.1, "y": None}]
    gryffin.build_surrogate(failed)
    near_failures, near_successes = {"x0": 0.93, "x1": 0.07}, {"x0": 0.3, "x1": 0.6}
    p = gryffin.get_feasibility_surrogate([near_failures, near_successes])
    assert p[0] < 0.5 < p[1]
    assert list(gryffin.get_feasibility_surrogate([near_failures, near_successes], threshold=0.5)) == [False, True]
    empty = {"x0": 0.05, "x1": 0.95}  # 0.43 from the nearest experiment
    split = gryffin.get_kernel_density_estimate([near_failures, near_successes, empty], separate_kwn_ukwn=True)
    total = gryffin.get_kernel_density_estimate([near_failures, near_successes, empty])
    assert split.shape == (3, 2) and np.allclose(split.sum(1), total)
    assert split[0, 1] > split[0, 0] and split[1, 0] > split[1, 1]  # failed kernels near the failures
    assert total[2] < total[1]  # far from every experiment
    acquisition = gryffin.get_acquisition([{"x0": 0.3, "x1": 0.6}, empty])
    assert sorted(acquisition) == [-1.0, 1.0]
    assert acquisition[1.0][0] < acquisition[1.0][1]  # exploitation prefers the best observation
    assert acquisition[-1.0][1] < acquisition[-1.0][0]  # exploration prefers the empty region


def test_descriptor_summaries():
    options = {f"o{i}": [float(i), float((3 * i) % 7)] for i in range(8)}
    config = {"general": {"auto_desc_gen": True, "random_seed": 0},
              "parameters": [{"name": "s", "type": "categorical", "category_details": options}],
              "objectives": [{"name": "y", "goal": "min"}]}
    gryffin = Gryffin(config_dict=config)
    observations = [{"s": f"o{i}", "y": float(i)} for i in range(7)]
    gryffin.build_surrogate(observations)
    summary = gryffin.get_descriptor_summary_regression()
    assert set(summary) == {"s"} and len(summary["s"]["relevance"]) == 2
    assert sum(summary["s"]["relevance"]) == pytest.approx(1.0, abs=1e-3)
    assert gryffin.get_descriptor_summary_feasibility() == {}  # nothing failed


# ---- the Gryffin scripts of the README and docs/gryffin1.md ---------------------------------------------------------
@pytest.mark.parametrize("document", ["README.md", "docs/gryffin1.md"])
def test_the_documented_gryffin_scripts_run(document):
    text = (ROOT / document).read_text()
    section = text.split("# Gryffin 1.0 users", 1)[1]
    script = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert script.startswith("from gryffin_ros.compat import Gryffin")
    namespace = {}
    exec(compile(script, document, "exec"), namespace)  # noqa: S102 - our own docs
    observations = namespace["observations"]  # every recommendation, with its result
    assert len(observations) == 6 and all(namespace["feasible"](o) for o in observations)
