"""The Gaussian-process surrogate (general.surrogate gp/auto): its inputs, its fit, its acquisition under the known
constraints, batches and pending experiments, failed experiments, the choice of `auto`, and reproducibility."""

import numpy as np
import pytest
import torch
from botorch.optim.utils import sample_all_priors
from gpytorch.kernels import MaternKernel
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gryffin_ros.planner import ConfigError, Planner
from gryffin_ros.planner.acquisition.gp import GPAcquisition
from gryffin_ros.planner.space import SearchSpace
from gryffin_ros.planner.surrogates import gaussian_process as gp_module
from gryffin_ros.planner.surrogates.gaussian_process import Features, GaussianProcess, fit_size, rank_correlation
from tests.conftest import branin, branin_feasible
from tests.planner.strategies.test_properties import exercise, problems


def bowl(p):
    return (p["x0"] - 0.3) ** 2 + (p["x1"] - 0.6) ** 2


def run(planner, n, objective):
    """n ask/tell rounds; the proposals made."""
    made = []
    for _ in range(n):
        for proposal in planner.ask():
            planner.tell({**proposal.params, "y": objective(proposal.params), "experiment_id": proposal.experiment_id})
            made.append(proposal)
    return made


def config(surrogate, **general):
    return {"parameters": [{"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                           {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}],
            "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": surrogate, **general}}


def test_features_map_every_kind_of_parameter_into_the_unit_cube():
    space = SearchSpace.from_config([
        {"name": "t", "type": "continuous", "low": 10, "high": 20},
        {"name": "angle", "type": "continuous", "low": 0, "high": 360, "periodic": True},
        {"name": "n", "type": "discrete", "options": [1, 2, 4, 8]},
        {"name": "solvent", "type": "categorical", "options": ["a", "b", "c"],
         "descriptors": {"a": [1.0, 5.0], "b": [3.0, 5.0], "c": [2.0, 5.0]}},
        {"name": "base", "type": "categorical", "options": ["x", "y"]}])
    features = Features(space)
    # t, angle (sin, cos), n, solvent's first descriptor (the constant second one tells nothing), base as a category
    assert features.dim == 6 and features.cat_dims == [5]
    X = space.to_internal([{"t": 15.0, "angle": 90.0, "n": 4, "solvent": "c", "base": "y"}])
    row = features.of(X).numpy()[0]
    np.testing.assert_allclose(row, [0.5, 1.0, 0.5, 3 / 7, 0.5, 1.0], atol=1e-12)
    # the angle's features agree at both ends of its period
    ends = space.to_internal([{"t": 10.0, "angle": a, "n": 1, "solvent": "a", "base": "x"} for a in (0.0, 360.0)])
    np.testing.assert_allclose(*features.of(ends).numpy(), atol=1e-12)



def test_descriptor_columns_of_categorical_parameters_keep_a_length_scale_floor():
    """The kernel's length scales may shrink to 1e-3 on continuous and ordinal inputs, but not below
    DESCRIPTOR_LENGTHSCALE_MIN on a categorical parameter's descriptor columns, even when the data pull them there:
    results that differ only between options 'a' and 'b', whose descriptors are close (0.05 apart), with the
    continuous input irrelevant."""
    space = SearchSpace.from_config([
        {"name": "t", "type": "continuous", "low": 0, "high": 1},
        {"name": "n", "type": "discrete", "options": [1, 2, 4, 8]},
        {"name": "solvent", "type": "categorical", "options": ["a", "b", "c"],
         "descriptors": {"a": [0.0], "b": [0.05], "c": [1.0]}}])
    floor = gp_module.DESCRIPTOR_LENGTHSCALE_MIN
    assert Features(space).lengthscale_floors.tolist() == [1e-3, 1e-3, floor]
    rng = np.random.default_rng(0)
    params = [{"t": float(rng.random()), "n": [1, 2, 4, 8][i % 4], "solvent": "ab"[i % 2]} for i in range(16)]
    y = np.array([1.0 if p["solvent"] == "a" else -1.0 for p in params])
    gp = GaussianProcess(space, space.to_internal(params), y, seed=0)
    lengthscale = gp.model.covar_module.base_kernel.lengthscale.detach().numpy().ravel()
    assert lengthscale[2] >= floor * (1 - 1e-9)
    assert lengthscale[2] < 2 * floor  # the data push it down to the floor: a floor that holds, not an idle one


def test_with_two_described_categorical_parameters_the_kernel_adds_each_one_s_main_effect():
    """Ligand and solvent with descriptors far apart (one-hot: the descriptors tell nothing), yield = ligand's effect
    + solvent's effect + a little of t. Ligand c and solvent c are each the best, seen only with other partners. The
    main-effect terms predict the untried c/c as the best combination, better than anything run; one product kernel
    (what the GP had before) cannot: c/c correlates with nothing it has seen, and it predicts c/c at about the mean."""
    options = ["a", "b", "c", "d", "e"]
    onehot = {o: [float(i == j) for j in range(5)] for i, o in enumerate(options)}
    space = SearchSpace.from_config([
        {"name": "t", "type": "continuous", "low": 0, "high": 1},
        {"name": "n", "type": "discrete", "options": [1, 2, 3]},
        {"name": "ligand", "type": "categorical", "options": options, "descriptors": onehot},
        {"name": "solvent", "type": "categorical", "options": options, "descriptors": onehot}])
    features = Features(space)
    # t, n (a discrete parameter: its ordinal position, not a group), then the two groups of five columns
    assert features.described_groups == [[2, 3, 4, 5, 6], [7, 8, 9, 10, 11]]
    ligand = {"a": 0.0, "b": 0.6, "c": -1.0, "d": 0.8, "e": 0.3}
    solvent = {"a": 0.5, "b": -0.2, "c": -1.0, "d": 0.9, "e": 0.0}
    pairs = [(a, b) for a in options for b in options if (a, b) != ("c", "c")]
    grid = space.to_internal([{"t": 0.5, "n": 2, "ligand": a, "solvent": b} for a in options for b in options])
    best_pair = options.index("c") * 5 + options.index("c")
    for seed in range(3):
        rng = np.random.default_rng(seed)
        params = [{"t": float(rng.random()), "n": int(rng.choice([1, 2, 3])), "ligand": a, "solvent": b}
                  for a, b in (pairs[i] for i in rng.permutation(len(pairs))[:14])]
        y = np.array([ligand[p["ligand"]] + solvent[p["solvent"]] + 0.5 * (p["t"] - 0.5) ** 2 for p in params])
        gp = GaussianProcess(space, space.to_internal(params), y, seed=0)
        assert len(gp.model.covar_module.kernels) == 3  # every interaction, the ligand's and the solvent's effect
        mean = gp.model.posterior(gp.features.of(grid)).mean.detach().numpy().ravel()
        assert int(np.argmin(mean)) == best_pair and mean[best_pair] < y.min()  # true value -2.0
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(gp_module, "MAIN_EFFECTS_MIN_PARAMETERS", 3)  # one product kernel over every input
            product = GaussianProcess(space, space.to_internal(params), y, seed=0)
            mean = product.model.posterior(product.features.of(grid)).mean.detach().numpy().ravel()
            assert int(np.argmin(mean)) != best_pair and mean[best_pair] > y.min()


def test_a_space_of_categorical_options_without_descriptors_fits_and_recommends():
    """Only options, no descriptors: no input has a Matern length scale (no floors at all), and the GP still fits,
    predicts the options it has seen in order, and recommends (an empty per-input bound once broke every ask of the
    paper's surfaces without descriptors)."""
    options = [f"x_{i}" for i in range(6)]
    config = {"parameters": [{"name": n, "type": "categorical", "options": options} for n in ("a", "b")],
              "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"}}
    space = SearchSpace.from_config(config["parameters"])
    assert Features(space).lengthscale_floors.numel() == 0
    params = [{"a": options[i % 6], "b": options[(i * 5 + 1) % 6]} for i in range(12)]
    y = np.array([float(options.index(p["a"])) for p in params])
    gp = GaussianProcess(space, space.to_internal(params), y, seed=0)
    mean = gp.model.posterior(gp.features.of(space.to_internal(params[:6]))).mean.detach().numpy().ravel()
    assert np.all(np.diff(mean) > 0)  # options a = x_0 ... x_5, results 0 ... 5
    planner = Planner(config, seed=0)
    planner.tell([{**p, "y": float(v)} for p, v in zip(params, y)])
    (proposal,) = planner.ask()
    assert proposal.params["a"] in options and proposal.meta.get("surrogate") == "gp"


def test_rank_correlation():
    a = np.array([1.0, 2.0, 3.0, 4.0])
    assert rank_correlation(a, a ** 3) == pytest.approx(1.0)
    assert rank_correlation(a, -a) == pytest.approx(-1.0)
    assert rank_correlation(a, np.ones(4)) == 0.0
    assert rank_correlation(np.array([1.0, 1.0, 2.0]), np.array([0.0, 0.0, 5.0])) == pytest.approx(1.0)


def test_fit_size_refits_early_then_every_tenth():
    assert [fit_size(n) for n in (1, 19, 20, 21, 22, 55, 100, 109)] == [1, 19, 20, 20, 22, 55, 100, 100]
    assert all(n - 10 < fit_size(n) <= n for n in range(1, 120))


def test_gp_interpolates_and_predicts_left_out_points_in_order():
    space = SearchSpace.from_config([{"name": "x0", "type": "continuous", "low": 0, "high": 1},
                                     {"name": "x1", "type": "continuous", "low": 0, "high": 1}])
    rng = np.random.default_rng(0)
    X = rng.random((25, 2))
    y = np.array([bowl({"x0": a, "x1": b}) for a, b in X])
    gp = GaussianProcess(space, X, y, seed=0)
    assert rank_correlation(gp.leave_one_out(), y) > 0.95
    alpha = GPAcquisition(gp).evaluate(np.array([[0.3, 0.6], [0.95, 0.05]]))
    assert alpha[0] < alpha[1]  # improvement is expected at the bowl's bottom, not in a far corner
    # the gradient used by Adam agrees with finite differences
    x = np.array([[0.4, 0.5]])
    _, grad = GPAcquisition(gp).value_and_grad(x)
    step = 1e-6
    numeric = [(GPAcquisition(gp).evaluate(x + step * e) - GPAcquisition(gp).evaluate(x - step * e))[0] / (2 * step)
               for e in np.eye(2)]
    np.testing.assert_allclose(grad[0], numeric, rtol=1e-3, atol=1e-6)


def test_gp_planner_finds_the_constrained_branin_minimum():
    planner = Planner(config("gp"), known_constraints=branin_feasible, seed=3)
    made = run(planner, 40, lambda p: branin(p["x0"], p["x1"]))
    assert len(made) == 40 and all(branin_feasible(p.params) for p in made)
    assert planner.best().objectives["y"] - 0.397887 < 0.01  # the kernel density needs ~100 for 0.4
    assert made[0].meta == {} and [p.meta["surrogate"] for p in made[1:5]] == ["random"] * 4
    # after 8 experiments without improvement an ask says it stalled (strategies/stall.py)
    assert all(p.meta["surrogate"] == "gp" and set(p.meta) <= {"surrogate", "stalled"} for p in made[5:])


def test_gp_batches_and_pending_experiments_are_spread_out():
    planner = Planner(config("gp"), seed=1)
    run(planner, 6, bowl)
    first = planner.ask(3)
    second = planner.ask(2)  # the first three are pending: believed, not proposed again
    points = np.array([[p.params["x0"], p.params["x1"]] for p in first + second])
    distances = np.sqrt(((points[:, None] - points[None]) ** 2).sum(-1))[np.triu_indices(5, 1)]
    assert distances.min() > 1e-3
    assert all(p.strategy is None and p.meta == {"surrogate": "gp"} for p in first + second)


def test_gp_on_a_finite_space_never_repeats_and_finds_the_corner():
    slope = {"parameters": [{"name": "x0", "type": "discrete", "low": 0, "high": 20},
                            {"name": "x1", "type": "discrete", "low": 0, "high": 20}],
             "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"},
             "constraints": ["not (5 < x0**2 + x1**2 < 25)"]}
    planner = Planner(slope, seed=0)
    for x0, x1 in [(16, 13), (17, 8), (7, 12), (16, 10), (20, 12)]:
        planner.tell({"x0": x0, "x1": x1, "y": x0 + x1})
    found = None
    for i in range(6):
        (proposal,) = planner.ask()
        planner.tell({**proposal.params, "y": proposal.params["x0"] + proposal.params["x1"],
                      "experiment_id": proposal.experiment_id})
        if (proposal.params["x0"], proposal.params["x1"]) == (0, 0):
            found = i + 1
            break
    assert found is not None and found <= 3
    seen = [(o.params["x0"], o.params["x1"]) for o in planner.observations]
    assert len(set(seen)) == len(seen)


def test_gp_with_categories_and_failed_experiments():
    mixed = {"parameters": [{"name": "x", "type": "continuous", "low": 0, "high": 1},
                            {"name": "c", "type": "categorical", "options": ["a", "b", "c"]}],
             "objectives": [{"name": "y", "goal": "min"}], "general": {"surrogate": "gp"},
             "constraints": ["c != 'c' or x < 0.5"]}
    planner = Planner(mixed, seed=2)
    rng = np.random.default_rng(0)
    for _ in range(12):
        (proposal,) = planner.ask()
        p = proposal.params
        assert p["c"] != "c" or p["x"] < 0.5
        failed = p["c"] == "b" and rng.random() < 0.8  # option b mostly fails
        planner.tell({**p, "y": None if failed else (p["x"] - 0.7) ** 2 + (p["c"] == "c"),
                      "experiment_id": proposal.experiment_id})
    late = [o.params["c"] for o in planner.observations[6:]]
    assert late.count("b") <= 2


def test_auto_compares_the_models_and_records_its_choice():
    planner = Planner(config("auto"), seed=0)
    early = run(planner, 4, bowl)[-1].meta
    assert early["surrogate"] == "kde" and "surrogate_reason" in early
    meta = run(planner, 12, bowl)[-1].meta
    scores = meta["loo_rank_correlation"]
    z_gp, z_kde = np.arctanh(min(scores["gp"], 0.999)), np.arctanh(min(scores["kde"], 0.999))
    assert meta["surrogate"] == ("gp" if z_gp - z_kde > np.sqrt(1.06 / (16 - 3)) else "kde")  # 16 distinct results
    assert meta["surrogate"] == "gp"  # on a smooth bowl the GP ranks the left-out points better
    assert scores["gp"] > 0.9


def test_auto_keeps_the_kernel_density_on_plateaus():
    """A step-shaped objective with 3 levels: ties rank nothing, so the score cannot favour the GP."""
    planner = Planner(config("auto"), seed=0)
    made = run(planner, 20, lambda p: float(min(2, int(3 * bowl(p)))))
    assert {p.meta["surrogate"] for p in made[1:]} == {"kde"}
    assert all("fewer than 5 distinct" in p.meta["surrogate_reason"] for p in made[1:])


def bowl3(p):
    return (p["x0"] - 0.3) ** 2 + (p["x1"] - 0.6) ** 2 + (p["x2"] - 0.5) ** 2


def config3(**general):
    return {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(3)],
            "objectives": [{"name": "y", "goal": "min"}], "general": general}


def test_portfolio_is_the_default_and_its_first_model_follows_the_shape_of_the_space():
    """No surrogate key: the portfolio. With 3 continuous parameters it starts from the GP (after the initial design,
    also before the models can be compared), with 2 from the kernel density; every proposal says which model made it
    and why."""
    assert Planner(config3()).config.general.surrogate == "portfolio"
    three = Planner(config3(), seed=0)
    made = run(three, 7, bowl3)
    assert [p.meta["surrogate"] for p in made[5:]] == ["gp"] * 2
    assert all("3 continuous parameter(s), GP first" in p.meta["surrogate_reason"] for p in made[5:])
    two = Planner({**config("kde"), "general": {}}, seed=0)
    made = run(two, 4, bowl)
    assert [p.meta["surrogate"] for p in made[1:]] == ["kde"] * 3
    assert all("kernel density first" in p.meta["surrogate_reason"] for p in made[1:])


def test_the_gp_proposes_from_five_distinct_results_random_feasible_points_before():
    """An initial design: an ask that the GP would make (`gp`, or the portfolio starting from it) proposes random
    feasible points until the successful experiments have GP_MIN_RESULTS distinct results; failed experiments and
    repeated results do not count, and the kernel density (two continuous parameters) is not held back."""
    from gryffin_ros.planner.surrogates.choice import GP_MIN_RESULTS
    assert GP_MIN_RESULTS == 5  # the results below give 4 distinct ones, then a 5th
    constrained = {**config3(), "constraints": ["x0 + x1 <= 1.2"]}
    for general in ({}, {"surrogate": "gp"}):
        planner = Planner({**constrained, "general": general}, seed=2)
        results = [None, 0.5, 0.5, None, 0.7, 0.2, 0.9]  # failures and a repeat: 4 distinct successful results
        for y in results:
            (proposal,) = planner.ask()
            assert proposal.params["x0"] + proposal.params["x1"] <= 1.2
            planner.tell({**proposal.params, "y": y, "experiment_id": proposal.experiment_id})
        made = planner.ask(2)
        assert all(p.meta["surrogate"] == "random" and "4 distinct successful result(s)" in p.meta["surrogate_reason"]
                   and p.params["x0"] + p.params["x1"] <= 1.2 for p in made), general
        planner.tell({**made[0].params, "y": 0.3, "experiment_id": made[0].experiment_id})
        assert planner.ask()[0].meta["surrogate"] == "gp", general
    two = Planner({**config("kde"), "general": {}}, seed=0)
    assert {p.meta["surrogate"] for p in run(two, 3, bowl)[1:]} == {"kde"}


def test_the_initial_design_ends_at_ten_successful_experiments_when_the_results_take_few_values():
    """An objective with three possible values (a rating of 0, 1 or 2) never has GP_MIN_RESULTS distinct results:
    the initial design ends after INITIAL_DESIGN_MAX successful experiments (failed ones do not count); then the
    portfolio proposes from the kernel density and says why, and `surrogate: gp` from the GP."""
    from gryffin_ros.planner.surrogates.choice import GP_MIN_RESULTS, INITIAL_DESIGN_MAX
    assert INITIAL_DESIGN_MAX == 10 and GP_MIN_RESULTS > 3
    for general, model in (({}, "kde"), ({"surrogate": "gp"}, "gp")):
        planner = Planner({**config3(), "general": general}, seed=3)
        ratings = [0.0, 1.0, None, 2.0, 0.0, 1.0, 1.0, None, 0.0, 2.0, 1.0]  # 9 successful, 3 distinct
        for y in ratings:
            (proposal,) = planner.ask()
            planner.tell({**proposal.params, "y": y, "experiment_id": proposal.experiment_id})
        (proposal,) = planner.ask()
        assert proposal.meta["surrogate"] == "random", general
        assert "3 distinct successful result(s)" in proposal.meta["surrogate_reason"]
        assert "from 10 successful experiments" in proposal.meta["surrogate_reason"]
        planner.tell({**proposal.params, "y": 2.0, "experiment_id": proposal.experiment_id})  # the 10th
        made = planner.ask(2)
        assert [p.meta["surrogate"] for p in made] == [model, model], general
        if model == "kde":
            assert "3 distinct results in 10 successful experiments" in made[0].meta["surrogate_reason"]


def test_portfolio_leaves_its_first_model_only_on_clear_evidence(monkeypatch):
    """With the GP first, the kernel density takes over only when its held-out ranking is better by more than the
    score's sampling error: a kernel density that ranks the observations perfectly takes over, one that ranks them
    like the GP does not."""
    from gryffin_ros.planner.surrogates.kernel_density import KernelDensity
    planner = Planner(config3(), seed=1)
    run(planner, 12, bowl3)
    merits = planner.merits([o for o in planner.observations if not o.failed])
    monkeypatch.setattr(KernelDensity, "leave_one_out", lambda self, at=None: np.asarray(merits))
    meta = planner.ask()[0].meta
    assert meta["surrogate"] == "kde" and meta["loo_rank_correlation"]["kde"] == 1.0
    assert "kernel density clearly better" in meta["surrogate_reason"]
    monkeypatch.setattr(KernelDensity, "leave_one_out", lambda self, at=None: -np.asarray(merits))
    meta = planner.ask()[0].meta
    assert meta["surrogate"] == "gp" and "kernel density not clearly better" in meta["surrogate_reason"]



def test_with_several_objectives_the_portfolio_keeps_the_kernel_density():
    """Chimera's merit steps at each tolerance: with two objectives the portfolio uses the kernel density even with 3
    continuous parameters and data a GP ranks well, says why, and proposes what `kde` proposes."""
    config = config3()
    config["objectives"] = [{"name": "y", "goal": "min", "tolerance": 0.1, "absolute": True},
                            {"name": "z", "goal": "min"}]
    made = run_two(Planner(config, seed=0), 10)
    for proposal in made:
        assert proposal.meta["surrogate"] == "kde"
        assert "2 objectives: the kernel density" in proposal.meta["surrogate_reason"]
    config["general"] = {"surrogate": "kde"}
    assert [p.params for p in run_two(Planner(config, seed=0), 10)] == [p.params for p in made]


def run_two(planner, n):
    made = []
    for _ in range(n):
        (proposal,) = planner.ask()
        planner.tell({**proposal.params, "y": bowl3(proposal.params), "z": proposal.params["x0"],
                      "experiment_id": proposal.experiment_id})
        made.append(proposal)
    return made[1:]

COUPLING = {"parameters": [{"name": "c", "type": "categorical", "options": ["a", "b", "c", "d"],
                            "descriptors": {"a": [0.0, 0.2], "b": [0.4, 1.0], "c": [1.0, 0.1], "d": [0.6, 0.5]}}]
            + [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(3)],
            "objectives": [{"name": "y", "goal": "min"}], "constraints": ["x0 + x1 <= 1.5"],
            "general": {"num_random_samples": 50}}


def plateau_campaign(seed, asks):
    """A mixed campaign whose results are a plateau near zero with one good result, in combination a (most
    combinations of a coupling give no product): its proposals."""
    rng = np.random.default_rng(0)
    planner = Planner(COUPLING, seed=seed)
    for i in range(12):
        x = rng.uniform(0.0, 0.7, 3)
        planner.tell({"c": "a" if i < 6 else "bcd"[i % 3], **{f"x{j}": float(v) for j, v in enumerate(x)},
                      "y": -0.7 if i == 0 else float(rng.normal(0.0, 0.01))})
    made = []
    for _ in range(asks):
        (proposal,) = planner.ask()
        made.append(proposal)
        planner.tell({**proposal.params, "y": float(rng.normal(0.0, 0.01)), "experiment_id": proposal.experiment_id})
    return made


def matern_without_prior(bounds, prior_inputs, ard_num_dims, batch_shape=None, active_dims=None):
    """The GP's kernel as it was before the length-scale prior: the marginal likelihood alone."""
    return MaternKernel(nu=2.5, ard_num_dims=ard_num_dims, batch_shape=batch_shape, active_dims=active_dims,
                        lengthscale_constraint=bounds)


def test_a_fit_retried_from_the_prior_draws_the_length_scales_that_have_one_within_their_bounds():
    """When no attempt of a fit converges, BoTorch retries from hyperparameters drawn from their priors
    (`sample_all_priors`; a prior registered without a way to set its values made every such retry raise, as on the
    paper's Branin while this prior was measured): the continuous input's and the
    descriptor column's length scales are drawn, within their bounds, and the ordinal input's is kept."""
    space = SearchSpace.from_config([
        {"name": "t", "type": "continuous", "low": 0, "high": 1},
        {"name": "n", "type": "discrete", "options": [1, 2, 4, 8]},
        {"name": "solvent", "type": "categorical", "options": ["a", "b", "c"],
         "descriptors": {"a": [0.0], "b": [0.5], "c": [1.0]}},
        {"name": "base", "type": "categorical", "options": ["x", "y"]}])
    assert Features(space).prior_inputs == [0, 2]
    rng = np.random.default_rng(0)
    params = [{"t": float(rng.random()), "n": [1, 2, 4, 8][i % 4], "solvent": "abc"[i % 3], "base": "xy"[i % 2]}
              for i in range(12)]
    gp = GaussianProcess(space, space.to_internal(params), rng.random(12), seed=0)
    kernels = [m for m in gp.model.covar_module.modules() if isinstance(m, MaternKernel)]
    before = [k.lengthscale.detach().clone().ravel() for k in kernels]
    torch.manual_seed(0)
    sample_all_priors(gp.model)
    for kernel, old in zip(kernels, before):
        new = kernel.lengthscale.detach().ravel()
        assert new[1] == old[1]  # the ordinal input: no prior, untouched
        assert (new[[0, 2]] != old[[0, 2]]).all()
        assert (new >= Features(space).lengthscale_floors).all() and (new <= gp_module.LENGTHSCALE_BOUNDS[1]).all()


def test_a_retry_from_the_prior_on_ten_inputs_sets_draws_beyond_the_bounds_just_inside_them():
    """Ten continuous inputs: the prior's median (~13) is near the upper bound (20), so a draw of all ten within the
    bounds is rare, and BoTorch, which draws again on every out-of-bounds error, gave up after 100 draws and failed
    the ask. Each draw is now taken as it is within the bounds and just inside them beyond."""
    space = SearchSpace.from_config([{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(10)])
    X = np.random.default_rng(0).random((20, 10))
    gp = GaussianProcess(space, X, X.sum(axis=1), seed=0)
    (kernel,) = [m for m in gp.model.covar_module.modules() if isinstance(m, MaternKernel)]
    low, high = gp_module.LENGTHSCALE_BOUNDS
    at_bound = 0
    for seed in range(5):
        torch.manual_seed(seed)
        sample_all_priors(gp.model)  # raised "Failed to sample a feasible parameter value" before
        drawn = kernel.lengthscale.detach().ravel()
        assert torch.isfinite(kernel.raw_lengthscale).all()
        assert (drawn > low).all() and (drawn < high).all()
        at_bound += int((drawn > 0.999 * high).sum())
        assert len(torch.unique(drawn)) > 3  # drawn, not set to one value
    assert at_bound > 0  # some draws were beyond the upper bound (P ~ 0.4 each, 50 draws)


def test_a_fit_that_explains_the_data_as_noise_is_repeated_from_short_length_scales(monkeypatch):
    """Without the length-scale prior, from BoTorch's start the marginal likelihood of these 8 points of a smooth bowl
    ends in its all-noise optimum (a near-constant model, whose expected improvement kept m_coupling's campaigns on
    their first good combination); the repeated fit from SHORT_START is kept: more likely, and with more signal than
    noise. The prior (on continuous inputs and descriptors; ordinal positions have none) avoids that optimum here on
    its own."""
    space = Planner(config3()).space
    X = np.random.default_rng(2).uniform(0.0, 1.0, (8, 3))
    y = np.array([bowl3({"x0": a, "x1": b, "x2": c}) for a, b, c in X])
    threshold = gp_module.MIN_SIGNAL_TO_NOISE
    monkeypatch.setattr(gp_module, "MIN_SIGNAL_TO_NOISE", 0.0)  # the first fit alone
    assert GaussianProcess(space, X, y, seed=0).signal_to_noise() > 1.0  # with the prior
    monkeypatch.setattr(gp_module, "matern_kernel", matern_without_prior)
    first = GaussianProcess(space, X, y, seed=0)
    assert first.signal_to_noise() < 0.01  # the collapse this guards against
    monkeypatch.setattr(gp_module, "MIN_SIGNAL_TO_NOISE", threshold)
    fitted = GaussianProcess(space, X, y, seed=0)
    assert fitted.signal_to_noise() > 1.0
    assert fitted.log_likelihood() > first.log_likelihood() + 0.5


def test_a_noisy_fit_with_some_signal_is_kept_as_it_is(monkeypatch):
    """Noisy results (a sine in x0 under noise of its own size): the fit's signal is about half its noise, which is a
    model, not a collapse (the flow reactor's noisy fits are like it, and repeating them left campaigns on a poor
    cost): no second fit is made. The kernel without the length-scale prior, as on a discrete parameter's levels
    (with the prior these data are fitted closely, noise 0.007, far above the threshold either way)."""
    monkeypatch.setattr(gp_module, "matern_kernel", matern_without_prior)
    space = Planner(config3()).space
    rng = np.random.default_rng(4)
    X = rng.uniform(0.0, 1.0, (30, 3))
    y = np.sin(4 * X[:, 0]) + rng.normal(0.0, 1.0, 30)
    repeated = []
    monkeypatch.setattr(gp_module, "short_start", lambda model: repeated.append(model))
    fitted = GaussianProcess(space, X, y, seed=0)
    assert gp_module.MIN_SIGNAL_TO_NOISE < fitted.signal_to_noise() < 1.0
    assert repeated == []


def settled_ridge(seed):
    """16 results of a yield-like ridge in [0, 1]^3 (peaked in x0, rising with x1 * x2) from a campaign that settled:
    half of them at the incumbent's x0; and 300 held-out points with their values."""
    def f(X):
        return -np.exp(-((X[:, 0] - 0.4) / 0.15) ** 2) * (1 - np.exp(-3 * X[:, 1] * X[:, 2] - 0.2))

    rng = np.random.default_rng(seed)
    X = rng.uniform(0.0, 1.0, (16, 3))
    X[8:, 0] = X[0, 0] + rng.normal(0.0, 0.002, 8)
    held_out = np.random.default_rng(99).uniform(0.0, 1.0, (300, 3))
    return X, f(X), held_out, f(held_out)


def held_out_ranking(space, seed):
    X, y, Xt, yt = settled_ridge(seed)
    gp = GaussianProcess(space, X, y, seed=0)
    mean, _ = gp.posterior.mean_and_sigma(gp.features.of(Xt))
    return rank_correlation(mean.detach().numpy(), yt)


def test_the_length_scale_prior_keeps_a_settled_campaign_s_fit_a_model(monkeypatch):
    """On these data the marginal likelihood alone ends, for some seeds, with one length scale at ~0.005 and the others
    at the upper bound (m_coupling's crawl: every temperature its own function): the GP then ranks held-out points no
    better than chance. With the log-normal length-scale prior every seed's GP ranks them (0.78-0.90 here; 0.6 is
    well clear of the ~0 without the prior)."""
    space = Planner(config3()).space
    seeds = (1, 3, 6)
    assert all(held_out_ranking(space, seed) > 0.6 for seed in seeds)
    monkeypatch.setattr(gp_module, "matern_kernel", matern_without_prior)
    assert min(held_out_ranking(space, seed) for seed in seeds) < 0.3  # the failure the prior is there for


def test_on_a_plateau_with_one_good_combination_the_campaign_tries_others():
    """Mostly near-zero results and one good one in combination a: the planner does not stay on a (with the GP's
    length-scale prior it first tries the good result's neighbourhood, 4-6 asks on seeds 0-3, then others), proposals
    are feasible, and the same seed and data give the same proposals."""
    made = plateau_campaign(seed=0, asks=10)
    assert len({p.params["c"] for p in made} - {"a"}) >= 2
    assert all(p.params["x0"] + p.params["x1"] <= 1.5 for p in made)
    again = plateau_campaign(seed=0, asks=10)
    for a, b in zip(made, again):
        assert a.params["c"] == b.params["c"]
        assert [a.params[f"x{i}"] for i in range(3)] == pytest.approx([b.params[f"x{i}"] for i in range(3)], abs=1e-9)


def test_gp_proposals_survive_a_restart_exactly():
    """Hyperparameters are refitted from the same first observations after a restart, so a restored planner proposes
    what the running one does, also between refits (25 observations: fitted to the first 24)."""
    running = Planner(config("gp"), seed=5)
    run(running, 25, bowl)
    assert fit_size(25) == 24
    restored = Planner(config("gp"), seed=5, history=running.history.snapshot())
    a, b = running.ask()[0].params, restored.ask()[0].params
    assert a == pytest.approx(b, abs=1e-9)


def test_missing_botorch_is_a_config_error(monkeypatch):
    monkeypatch.setattr(gp_module, "_IMPORT_ERROR", ImportError("No module named 'botorch'"))
    for setting in ("gp", "portfolio", "auto"):
        with pytest.raises(ConfigError, match=r"need BoTorch.*pip install 'botorch>=0.12', or general.surrogate: kde"):
            Planner(config(setting))
    Planner(config("kde"))  # the kernel density does not need it


def test_unknown_surrogate_is_refused():
    with pytest.raises(ConfigError, match="'general.surrogate' must be one of"):
        Planner(config("forest"))


@settings(max_examples=8, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(problem=problems(), surrogate=st.sampled_from(["gp", "auto", "portfolio"]),
       optimizer=st.sampled_from(["adam", "genetic"]),
       seed=st.integers(0, 2**31))
def test_gp_proposals_are_always_feasible_in_bounds_and_typed(problem, surrogate, optimizer, seed):
    specs, texts, _, _ = problem
    planner = Planner({"parameters": specs, "objectives": [{"name": "y", "goal": "min"}], "constraints": texts,
                       "general": {"surrogate": surrogate, "acquisition_optimizer": optimizer,
                                   "num_random_samples": 15}}, seed=seed)
    exercise(planner, problem, rounds=7, seed=seed)


@pytest.mark.parametrize("categorical", [False, True])
def test_posterior_agrees_with_botorch_also_after_believed_points(categorical):
    """The planner's own posterior (one cross-kernel matrix, a Cholesky factor extended per believed point) is the
    same GP as BoTorch's posterior and its condition_on_observations: means and standard deviations agree to 1e-6
    (standardized units; the two do the same algebra in a different order, so they differ by rounding only, ~1e-12
    here; a wrong kernel, noise or mean term moves them by > 1e-2)."""
    import torch
    parameters = [{"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                  {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}]
    if categorical:
        parameters.append({"name": "c", "type": "categorical", "options": ["a", "b", "c"]})
    space = SearchSpace.from_config(parameters)
    rng = np.random.default_rng(3)
    X = rng.random((25, space.dim))
    if categorical:
        X[:, 2] = rng.integers(0, 3, 25)
    y = np.sin(5 * X[:, 0]) + X[:, 1] ** 2 + (X[:, 2] if categorical else 0.0)
    gp = GaussianProcess(space, X, y, seed=1)
    Z = rng.random((40, space.dim))
    if categorical:
        Z[:, 2] = rng.integers(0, 3, 40)
    believed = rng.random((3, space.dim))
    if categorical:
        believed[:, 2] = rng.integers(0, 3, 3)
    model = gp.model
    for step in range(2):
        features = gp.features.of(Z)
        mean, sigma = gp.posterior.mean_and_sigma(features)
        with torch.no_grad():
            reference = model(features)  # the latent GP in standardized units (no outcome transform)
        np.testing.assert_allclose(mean.detach().numpy(), reference.mean.numpy(), atol=1e-6)
        np.testing.assert_allclose(sigma.detach().numpy(), reference.variance.sqrt().numpy(), atol=1e-6)
        if step == 0:
            gp.believe(believed)
            inputs = gp.features.of(believed)
            with torch.no_grad():
                fantasy = model(inputs).mean  # standardized, like model.train_targets
            model = model.get_fantasy_model(inputs, fantasy)


def test_hyperparameters_are_fitted_to_the_best_and_a_seeded_draw_of_the_rest_beyond_fit_max():
    from gryffin_ros.planner.surrogates.gaussian_process import FIT_BEST, FIT_MAX, fit_subset
    y = np.random.default_rng(0).random(FIT_MAX + 200)
    assert np.array_equal(fit_subset(y[:FIT_MAX], seed=1), np.arange(FIT_MAX))  # small campaigns: every observation
    subset = fit_subset(y, seed=1)
    assert len(subset) == FIT_MAX and len(set(subset)) == FIT_MAX and np.all(np.diff(subset) > 0)
    assert set(np.argsort(y)[:FIT_BEST]) <= set(subset)  # the best ones are always in
    assert np.array_equal(subset, fit_subset(y, seed=1))  # the same draw after a restart
    assert not np.array_equal(subset, fit_subset(y, seed=2))


class FixedAcquisition:
    """An acquisition whose values at the candidates are given: -log EI (log_scale) or the kernel acquisition."""

    def __init__(self, values, log_scale=True):
        self.values, self.log_scale = np.array(values), log_scale

    def evaluate(self, X):
        return self.values


class FixedFeasibility:
    """A failure model whose P(feasible) at the candidates is given."""
    fraction_failed = 0.5

    def __init__(self, p):
        self.p = np.array(p)

    def probability(self, X):
        return self.p


def scores(approach, values, p, log_scale=True):
    """The planner's scores of three candidates with the given acquisition values and P(feasible) (exhaustive: as
    they are, no optimization)."""
    planner = Planner(config("gp", feas_approach=approach), seed=0)
    candidates = np.array([[0.1, 0.1], [0.5, 0.5], [0.9, 0.9]])
    _, alpha = planner._candidates(FixedAcquisition(values, log_scale), candidates, True, None,
                                   np.random.default_rng(0), FixedFeasibility(p))
    return alpha


def test_with_failures_the_gp_weights_expected_improvement_by_the_probability_of_success():
    """fwa with the GP: -log EI - log P (constrained EI), so halving P(feasible) costs log 2 whatever EI is; fwt (the
    default): -log EI, its tail beyond EI_FLOOR_NATS compressed by EI_TAIL_SLOPE, - FEASIBILITY_POWER log min(1, P /
    0.5); the kernel acquisition keeps Gryffin's rescaled -(1 - a) P."""
    from gryffin_ros.planner.strategies.gryffin import EI_FLOOR_NATS, EI_TAIL_SLOPE, FEASIBILITY_POWER
    values, p = [3.0, 1.0, 7.0], [0.5, 0.25, 1.0]
    alpha = scores("fwa", values, p)
    np.testing.assert_allclose(alpha, [3.0 + np.log(2), 1.0 + np.log(4), 7.0], rtol=1e-12)
    alpha = scores("fwa", values, p, log_scale=False)
    np.testing.assert_allclose(alpha, [-(1 - 1 / 3) * 0.5, -1.0 * 0.25, 0.0], rtol=1e-12)
    assert Planner(config("gp"), seed=0).config.general.feas_approach == "fwt" and FEASIBILITY_POWER > 1
    alpha = scores("fwt", values, p)
    assert 3.0 < EI_FLOOR_NATS < 7.0 and 0 < EI_TAIL_SLOPE < 1
    tail = EI_FLOOR_NATS + EI_TAIL_SLOPE * (7.0 - EI_FLOOR_NATS)
    np.testing.assert_allclose(alpha, [3.0, 1.0 + FEASIBILITY_POWER * np.log(2), tail], rtol=1e-12)


def test_with_failures_a_negligible_expected_improvement_does_not_outweigh_the_risk_of_failing():
    """fwt's compressed tail of -log EI: where every candidate's EI is negligible (a settled campaign), a candidate
    among failures (P = 0.1) whose EI is e^-6 loses to a likely feasible one at e^-20; without it (fwa's constrained
    EI, and fwt before it) the first wins. A substantial EI (e^-1) at P = 0.3 still beats e^-20 at P = 1; among likely
    feasible candidates the order stays EI's, and in the tail too: an untried option at e^-200 and P = 0.3 still
    beats one at e^-2000 and P = 1 (a flat floor on EI ranked those by P alone)."""
    alpha = scores("fwt", [6.0, 20.0, 30.0], [0.1, 1.0, 1.0])
    assert int(np.argmin(alpha)) == 1
    assert alpha[1] < alpha[2]  # 20 and 30 nats: both in the tail, still in EI's order
    assert int(np.argmin(scores("fwa", [6.0, 20.0, 30.0], [0.1, 1.0, 1.0]))) == 0
    assert int(np.argmin(scores("fwt", [1.0, 20.0, 30.0], [0.3, 1.0, 1.0]))) == 0
    assert int(np.argmin(scores("fwt", [200.0, 2000.0, 3000.0], [0.3, 1.0, 1.0]))) == 0


def test_a_failed_experiment_is_believed_no_better_than_the_incumbent():
    """A failure where the GP, extrapolating the successes' trend, expects a better result than the best one is
    believed at the incumbent, not at its mean: the mean there rises most of the way to the incumbent and the expected
    improvement there falls by orders of magnitude; a pending experiment at the same point is believed at its mean,
    which leaves the mean where it was."""
    space = SearchSpace.from_config(config("gp")["parameters"])
    rng = np.random.default_rng(5)
    X = rng.random((20, 2)) * 0.5  # successes in the lower-left quarter only, the slope going on down beyond them
    y = -(X[:, 0] + X[:, 1])
    gp, pending = GaussianProcess(space, X, y, seed=0), GaussianProcess(space, X, y, seed=0)
    failed = np.array([[0.9, 0.9]])
    z = gp.features.of(failed)

    def mean_at(model):
        with torch.no_grad():
            return float(model.posterior.mean_and_sigma(z)[0])

    before, best, ei_before = mean_at(gp), gp.posterior.best, GPAcquisition(gp).evaluate(failed)[0]  # -log EI
    assert before < best  # the GP expects an improvement there
    gp.believe(failed, incumbent=False)
    pending.believe(failed)
    assert gp.posterior.best == best  # a failure never becomes the incumbent
    assert mean_at(gp) > before + 0.5 * (best - before)
    assert abs(mean_at(pending) - before) < 0.1 * (best - before)
    assert GPAcquisition(gp).evaluate(failed)[0] > ei_before + 2.0  # EI at least e^2 times smaller


def test_a_gp_batch_keeps_its_points_apart():
    """A batch of 12 from a GP that knows the optimum well: no two of its points are closer than a quarter of the
    even spacing of 12 points (kriging believer alone put whole batches next to the incumbent)."""
    from gryffin_ros.planner.strategies.selection import batch_spacing
    planner = Planner(config3(surrogate="gp"), seed=3)
    rng = np.random.default_rng(3)
    planner.tell([{**dict(zip(("x0", "x1", "x2"), map(float, x))), "y": bowl3(dict(zip(("x0", "x1", "x2"), x)))}
                  for x in rng.random((60, 3))])
    batch = planner.ask(12)
    X = np.array([[p.params[f"x{i}"] for i in range(3)] for p in batch])
    d = np.sqrt(((X[:, None] - X[None]) ** 2).sum(-1))[np.triu_indices(12, 1)]
    assert d.min() >= batch_spacing(planner.space, 12, planner.feasible_fraction.value) - 1e-12
    assert batch_spacing(planner.space, 12, 1.0) == pytest.approx(0.25 * 12 ** (-1 / 3))


def test_above_cond_max_the_gp_is_conditioned_on_the_best_and_a_draw_and_both_models_are_scored_there(monkeypatch):
    """Past COND_MAX observations the GP is conditioned on COND_MAX of them, always including the COND_BEST best,
    and the portfolio compares the two models on those same observations."""
    monkeypatch.setattr(gp_module, "COND_MAX", 20)
    monkeypatch.setattr(gp_module, "COND_BEST", 5)
    planner = Planner(config3(), seed=2)
    run(planner, 30, bowl3)
    successful = [o for o in planner.observations if not o.failed]
    X = planner.observed_points()
    gp = planner.surrogate_choice.gaussian_process(X, successful, {})
    merits = planner.surrogate_choice.raw_merits(successful)
    assert len(gp.conditioned) == 20 and len(set(gp.conditioned.tolist())) == 20
    assert set(np.argsort(merits, kind="stable")[:5].tolist()) <= set(gp.conditioned.tolist())
    assert len(gp.leave_one_out()) == 20
    proposal = planner.ask()[0]
    assert set(proposal.meta["loo_rank_correlation"]) == {"kde", "gp"}


def test_stateless_recommend_reuses_a_fit_of_the_same_data_and_proposes_what_a_fresh_fit_would(monkeypatch):
    """A Gryffin 1.0 script calls recommend on a growing list: each call is a fresh planner, but a fit of the same
    first observations is looked up instead of made again; the proposals are those of a planner that fits anew."""
    rng = np.random.default_rng(0)
    rows = [{"x0": float(a), "x1": float(b), "y": bowl({"x0": a, "x1": b})} for a, b in rng.random((24, 2))]
    assert fit_size(22) == fit_size(23) == 22
    planner = Planner(config("gp"), seed=1)
    planner.recommend(rows[:22])
    fits = []  # GPs made without hyperparameters: fitted
    real_init = GaussianProcess.__init__

    def counted(self, space, X, y, seed, descriptors=None, hyperparameters=None):
        fits.extend([1] if hyperparameters is None else [])
        real_init(self, space, X, y, seed, descriptors, hyperparameters)
    monkeypatch.setattr(GaussianProcess, "__init__", counted)
    warm = planner.recommend(rows[:23])
    assert fits == []  # the fit of the first 22 was reused
    cold = Planner(config("gp"), seed=1).recommend(rows[:23])
    assert fits == [1]
    assert [p["x0"] for p in warm] == pytest.approx([p["x0"] for p in cold], abs=1e-9)
    assert [p["x1"] for p in warm] == pytest.approx([p["x1"] for p in cold], abs=1e-9)
    other = [dict(r, y=r["y"] + 1.0 if i == 3 else r["y"]) for i, r in enumerate(rows[:23])]
    planner.recommend(other)  # another result among the first 22: fitted anew
    assert fits == [1, 1]


def test_with_several_objectives_a_fit_depends_on_its_first_observations_alone():
    """Chimera's merits depend on the range of every observation: the hyperparameters between refits are fitted to
    the first observations ranked among themselves, so a planner told them later proposes as one that was there."""
    cfg = config("gp")
    cfg["objectives"] = [{"name": "y", "goal": "min", "tolerance": 0.5, "absolute": False},
                         {"name": "z", "goal": "max"}]
    running = Planner(cfg, seed=4)
    for i in range(25):
        (proposal,) = running.ask()
        p = proposal.params
        y = 100.0 if i == 24 else bowl(p)  # the last one widens y's range: the relative tolerance moves
        running.tell({**p, "y": y, "z": p["x0"], "experiment_id": proposal.experiment_id})
    assert fit_size(25) == 24
    restored = Planner(cfg, seed=4, history=running.history.snapshot())
    a, b = running.ask()[0].params, restored.ask()[0].params
    assert a == pytest.approx(b, abs=1e-9)
