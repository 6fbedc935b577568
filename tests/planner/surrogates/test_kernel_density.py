"""The kernel-density surrogate: kernels sit where the observations are, in any units and dimension."""

import numpy as np
import pytest
import torch

from gryffin_ros.planner import Planner, SearchSpace
from gryffin_ros.planner.acquisition.kernel import Acquisition
from gryffin_ros.planner.surrogates.kernel_density import DTYPE, KernelDensity, concrete_table, mirror


def density_for(space, X, merits, fraction=1.0, seed=0):
    return KernelDensity(space, X, merits, fraction, torch.Generator().manual_seed(seed))


def split(space, X):
    return (torch.as_tensor(X[:, space.cont_idx], dtype=DTYPE),
            torch.as_tensor(np.rint(X[:, space.finite_idx]), dtype=torch.long))


@pytest.mark.parametrize("dim", [1, 2, 3, 4, 5])
def test_kernels_peak_at_their_observation_in_users_units(dim):
    """Gryffin 1.0 collapses kernels onto one point in >= 2-D and misreads units outside [0, 1]; ours must not."""
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 100.0, "high": 150.0}
                             for i in range(dim)], "objectives": [{"name": "y", "goal": "min"}]}
    planner = Planner(config, seed=dim)
    rng = np.random.default_rng(dim)
    rows = [{f"x{i}": float(v) for i, v in enumerate(x)} for x in rng.uniform(110, 140, (12, dim))]
    planner.tell([{**row, "y": float(sum(row.values()))} for row in rows])
    X = planner.space.to_internal(rows)
    merits = planner.merits(planner.observations)
    density = density_for(planner.space, X, merits)
    # each kernel is largest at its own observation, among all observations and a random cloud
    probes = np.concatenate([X, rng.random((500, dim))])
    log_p = density.log_kernels(*split(planner.space, probes))[:, :12]
    assert (log_p.argmax(dim=0).numpy() == np.arange(12)).all()
    # the regression surrogate reproduces the merits at the observations (kernels do not collapse together)
    fitted = density.regression(*split(planner.space, X)).numpy()
    assert np.corrcoef(fitted, merits)[0, 1] > 0.95
    assert np.median(np.abs(fitted - merits)) < 0.01


def test_kernels_narrow_as_observation_density_grows():
    space = SearchSpace.from_config([{"name": "x", "type": "continuous", "low": 0, "high": 1}])
    few = density_for(space, np.array([[0.5], [0.9]]), np.array([0.0, 1.0]))
    constrained = density_for(space, np.array([[0.5], [0.9]]), np.array([0.0, 1.0]), fraction=0.25)
    assert constrained.precision == pytest.approx(16 * few.precision)  # rho = n / V_C enters squared


def test_mirroring_near_bounds_makes_all_combinations():
    space = SearchSpace.from_config([{"name": "a", "type": "continuous", "low": 0, "high": 1},
                                     {"name": "b", "type": "continuous", "low": 0, "high": 1},
                                     {"name": "p", "type": "continuous", "low": 0, "high": 1, "periodic": True}])
    X, values = mirror(space, np.array([[0.02, 0.95, 0.01], [0.5, 0.5, 0.5]]), np.array([0.3, 0.7]))
    copies = {tuple(np.round(x, 6)) for x in X}
    assert copies == {(0.02, 0.95, 0.01), (-0.02, 0.95, 0.01), (0.02, 1.05, 0.01), (-0.02, 1.05, 0.01),
                      (0.5, 0.5, 0.5)}
    assert sorted(values.tolist()) == [0.3, 0.3, 0.3, 0.3, 0.7]


def test_categorical_kernel_peaks_at_the_observed_option_and_sharpens_with_data():
    gen = torch.Generator().manual_seed(0)
    broad = concrete_table(np.array([2]), 5, temperature=0.5 + 10 / 1.0, descriptors=None, generator=gen)[0]
    sharp = concrete_table(np.array([2]), 5, temperature=0.5 + 10 / 50.0, descriptors=None, generator=gen)[0]
    assert int(broad.argmax()) == 2 and int(sharp.argmax()) == 2
    assert float(sharp[2]) > float(broad[2])
    assert float(sharp.sum()) == pytest.approx(1.0)


def test_ordinal_descriptors_make_near_options_likelier_than_far_ones():
    gen = torch.Generator().manual_seed(0)
    descriptors = (np.arange(11) / 10.0)[:, None]
    row = concrete_table(np.array([5]), 11, 0.6, descriptors, gen)[0].numpy()
    assert row.argmax() == 5
    assert row[4] > row[2] > row[0] and row[6] > row[8] > row[10]


def test_acquisition_limits_far_from_and_at_the_data():
    space = SearchSpace.from_config([{"name": "x", "type": "continuous", "low": 0, "high": 1},
                                     {"name": "y", "type": "continuous", "low": 0, "high": 1}])
    grid = np.linspace(0.1, 0.5, 5)
    X = np.array([[a, b] for a in grid for b in grid])
    merits = np.linspace(0.0, 1.0, len(X))  # X[0] = (0.1, 0.1) is the best, X[-1] = (0.5, 0.5) the worst
    density = density_for(space, X, merits)
    probes = np.array([X[0], X[-1], [0.9, 0.9]])
    exploit, explore = Acquisition(density, 1.0).evaluate(probes), Acquisition(density, -1.0).evaluate(probes)
    assert exploit[0] == pytest.approx(0.0, abs=0.01) and exploit[1] == pytest.approx(1.0, abs=0.01)
    assert exploit[2] == pytest.approx(1.0, abs=1e-6)  # nothing known there: alpha = s
    assert explore[2] == pytest.approx(-1.0, abs=1e-6)
    assert explore[0] > explore[2] and exploit[0] < exploit[2]


def test_the_uniform_prior_counts_as_prior_weight_observations():
    """alpha = (sum_k f_k p_k + s w u) / (sum_k p_k + w u): with w = 3 the prior pulls alpha towards s as three
    observations spread over the space would; the failure model's wide estimate uses WIDE_PRIOR_WEIGHT."""
    from gryffin_ros.planner.acquisition.feasibility import WIDE_PRIOR_WEIGHT
    space = SearchSpace.from_config([{"name": "x", "type": "continuous", "low": 0, "high": 1}])
    X = np.array([[0.3], [0.35]])
    density = KernelDensity(space, X, np.array([0.0, 0.0]), 1.0, torch.Generator().manual_seed(0),
                            spacing_scaled=True)
    probes = np.array([[0.3], [0.5], [0.999]])
    kernels = torch.exp(density.log_kernels(*split(space, probes))).sum(1).numpy()  # sum_k p_k, the uniform u = 1
    for w in (1.0, 3.0):
        alpha = Acquisition(density, 1.0, prior_weight=w).evaluate(probes)
        # merits 0, s = 1; float64 sums of the same terms in another order (log space there): 1e-9 is far above that
        np.testing.assert_allclose(alpha, w / (kernels + w), rtol=1e-9)
    assert Acquisition(density, 1.0, 3.0).evaluate(probes)[1] > Acquisition(density, 1.0).evaluate(probes)[1]
    assert WIDE_PRIOR_WEIGHT > 1


def test_spacing_scaled_kernels_fill_the_gaps_between_observations():
    """Gryffin's 12 rho^2 kernels leave alpha = s (flat) between observations; the spacing-scaled kernels that
    general.kernel_width = auto/spacing uses interpolate there, so the acquisition ranks the gaps."""
    space = SearchSpace.from_config([{"name": "x", "type": "continuous", "low": 0, "high": 1},
                                     {"name": "y", "type": "continuous", "low": 0, "high": 1}])
    grid = np.linspace(0.1, 0.9, 5)
    X = np.array([[a, b] for a in grid for b in grid])
    merits = X.sum(axis=1) / 2  # better towards (0, 0)
    gaps = np.array([[0.2, 0.2], [0.8, 0.8], [0.4, 0.6]])
    narrow = Acquisition(density_for(space, X, merits), 1.0).evaluate(gaps)
    wide_density = KernelDensity(space, X, merits, 1.0, torch.Generator().manual_seed(0), spacing_scaled=True,
                                 spacing_factor=16.0)
    wide = Acquisition(wide_density, 1.0).evaluate(gaps)
    assert np.allclose(narrow, 1.0, atol=1e-6)
    assert wide[0] < wide[2] < wide[1] < 1.0
    assert wide_density.precision == pytest.approx(16.0 * len(mirror(space, X, merits)[0]))


@pytest.mark.parametrize("width, dims, spacing", [("auto", 2, True), ("auto", 6, False), ("spacing", 6, True),
                                                  ("gryffin", 2, False)])
def test_kernel_width_setting(width, dims, spacing):
    config = {"parameters": [{"name": f"x{i}", "type": "continuous", "low": 0, "high": 1} for i in range(dims)],
              "objectives": [{"name": "y", "goal": "min"}], "general": {"kernel_width": width}}
    assert Planner(config, seed=0).spacing_kernels is spacing


def test_kernel_width_rejects_unknown_values():
    from gryffin_ros.planner import ConfigError
    config = {"parameters": [{"name": "x", "type": "continuous", "low": 0, "high": 1}],
              "objectives": [{"name": "y", "goal": "min"}], "general": {"kernel_width": "wide"}}
    with pytest.raises(ConfigError, match="kernel_width"):
        Planner(config)


def test_concrete_temperature_sets_how_sharply_a_few_observations_pin_their_option():
    space = SearchSpace.from_config([{"name": "n", "type": "discrete", "low": 0, "high": 20}])
    X = np.array([[14.0]])
    tables = {c: torch.exp(KernelDensity(space, X, np.zeros(1), 1.0, torch.Generator().manual_seed(0),
                                         temperature_scale=c).tables[0][0]).numpy() for c in (10.0, 0.0)}
    assert tables[0.0][14] > tables[10.0][14]
    assert abs(int(np.argmax(tables[0.0])) - 14) < abs(int(np.argmax(tables[10.0])) - 14)  # less pull to the middle


def test_concrete_temperature_setting_is_validated_and_used():
    config = {"parameters": [{"name": "n", "type": "discrete", "low": 0, "high": 20}],
              "objectives": [{"name": "y", "goal": "min"}]}
    assert Planner(config).config.general.concrete_temperature == 0.0
    from gryffin_ros.planner import ConfigError
    for bad in (-1.0, float("inf"), "warm"):
        with pytest.raises(ConfigError, match="concrete_temperature"):
            Planner({**config, "general": {"concrete_temperature": bad}})
