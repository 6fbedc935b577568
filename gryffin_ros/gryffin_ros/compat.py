"""Gryffin 1.0's ``Gryffin`` class, as a thin adapter over :class:`gryffin_ros.planner.Planner`.

A Gryffin 1.0 script runs unchanged but for its import line::

    from gryffin_ros.compat import Gryffin      # was: from gryffin import Gryffin

    gryffin = Gryffin(config_dict=config, known_constraints=is_feasible, silent=True)
    samples = gryffin.recommend(observations, sampling_strategies=[-1])

Everything is computed by the Planner (its config format is Gryffin's, so Gryffin configs load unchanged); this
module only translates the calls. What differs from Gryffin 1.0 is listed in docs/gryffin1.md.
"""

from __future__ import annotations

import csv
import json
import logging
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import torch

from .planner.acquisition.kernel import Acquisition
from .planner.config import PlannerConfig, load_config, read_config
from .planner.errors import ConfigError, GryffinRosError, ObservationError
from .planner.strategies.base import OBJ_TRANSFORMS
from .planner.strategies.gryffin import SPACING_FACTOR, Planner, Surrogates
from .planner.surrogates.kernel_density import KernelDensity, split

__all__ = ["Gryffin", "UnsupportedError"]

LOGGER = logging.getLogger("gryffin_ros.compat")


class UnsupportedError(GryffinRosError, NotImplementedError):
    """A Gryffin 1.0 feature this project does not have; the message names what to use instead."""


def _rows(params: Any) -> list[Mapping[str, Any]]:
    """Gryffin's read-out argument: a list of parameter dicts, one dict, or a pandas DataFrame (duck-typed)."""
    if isinstance(params, Mapping):
        return [params]
    if hasattr(params, "to_dict") and hasattr(params, "columns"):
        return list(params.to_dict("records"))
    return list(params)


def _category_details(spec: Mapping[str, Any], position: int) -> Mapping[str, Any]:
    """A categorical parameter with Gryffin's `category_details` as Gryffin reads it: a JSON or CSV file name is
    loaded (options, then descriptors), and a table in which any option has no descriptors (None or []) means no
    descriptors at all."""
    details = spec.get("category_details")
    if isinstance(details, str):
        path = Path(details)
        if path.suffix not in (".json", ".csv"):
            raise ConfigError(f"parameters[{position}]: 'category_details' file '{details}': only .json and .csv "
                              "files are read here; convert it, or give the mapping option -> descriptors")
        try:
            if path.suffix == ".json":
                details = json.loads(path.read_text())
            else:
                with path.open(newline="") as handle:
                    details = {row[0]: [float(v) for v in row[1:]] for row in csv.reader(handle) if row}
        except (OSError, ValueError) as exc:
            raise ConfigError(f"parameters[{position}]: cannot read 'category_details' file '{details}': {exc}") \
                from None
        if not isinstance(details, Mapping):
            raise ConfigError(f"parameters[{position}]: 'category_details' file '{spec['category_details']}' must "
                              "hold a mapping option -> descriptors")
    if isinstance(details, Mapping) and any(v is None or (isinstance(v, (list, tuple)) and not v)
                                            for v in details.values()):
        if any(v for v in details.values() if isinstance(v, (list, tuple))):
            LOGGER.warning("parameter '%s': some options have no descriptors, so none are used (as in Gryffin)",
                           spec.get("name"))
        details = {option: None for option in details}
    return {**spec, "category_details": details} if details is not spec.get("category_details") else spec


def _discrete_stride(spec: Mapping[str, Any], position: int) -> Mapping[str, Any]:
    """A discrete parameter with a `stride` (as Olympus writes Gryffin configs): the options low, low + stride, ...,
    high. Gryffin 1.0 itself ignores the key (stride 1)."""
    if "stride" not in spec:
        return spec
    spec = dict(spec)
    stride = spec.pop("stride")
    if stride in (1, None):
        return spec
    low, high = spec.get("low"), spec.get("high")
    numbers = (stride, low, high)
    if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in numbers) or not stride > 0 or \
            not low < high:
        raise ConfigError(f"parameters[{position}]: a discrete 'stride' needs numbers low < high and stride > 0, got "
                          f"low={low!r}, high={high!r}, stride={stride!r}")
    count = int(np.floor((high - low) / stride + 1e-9)) + 1
    options = [low + k * stride for k in range(count)]
    if all(isinstance(v, int) for v in numbers):
        options = [int(v) for v in options]
    del spec["low"], spec["high"]
    return {**spec, "options": options}


class Gryffin:
    """Gryffin 1.0's interface: ``Gryffin(config_file=None, config_dict=None, known_constraints=None, frac_feas=None,
    silent=False)``; ``recommend``, ``build_surrogate``, ``frac_feas`` and the read-outs of the last model.

    - ``config_dict`` wins when both it and ``config_file`` (JSON or YAML) are given, as in Gryffin.
    - ``known_constraints``: a callable ``params -> bool`` or a list of them (the config's ``constraints`` list, our
      extension, is combined with them by AND).
    - ``frac_feas`` replaces the estimated feasible fraction when there are known constraints (Gryffin ignores it
      without any); ``silent`` is accepted: nothing is printed in any case (notes go to Python's ``logging``).
    - ``planner`` is the Planner doing the work; ``config`` its validated configuration.
    """

    def __init__(self, config_file: str | Path | None = None, config_dict: Mapping | None = None,
                 known_constraints: Callable[[dict], bool] | Sequence[Callable[[dict], bool]] | None = None,
                 frac_feas: float | None = None, silent: bool = False):
        if config_dict is not None:
            if config_file is not None:
                LOGGER.warning("both config_file and config_dict given: config_dict is used, config_file ignored "
                               "(as in Gryffin)")
            raw, base_dir = read_config(config_dict), None
        elif config_file is not None:
            raw, base_dir = read_config(config_file), Path(config_file).resolve().parent
        else:
            raise ConfigError("Gryffin needs a config_file or a config_dict")
        if isinstance(raw.get("parameters"), list):
            raw["parameters"] = [
                _category_details(p, i) if isinstance(p, Mapping) and p.get("type") == "categorical" else
                _discrete_stride(p, i) if isinstance(p, Mapping) and p.get("type") == "discrete" else p
                for i, p in enumerate(raw["parameters"])]
        if frac_feas is not None and (known_constraints is not None or raw.get("constraints")):
            general = raw.get("general")
            raw["general"] = {**(general if isinstance(general, Mapping) else {}), "feasible_fraction": frac_feas}
        self.silent = bool(silent)
        general = raw.get("general", {})
        if isinstance(general, Mapping):  # (anything else is left for load_config to refuse)
            # Gryffin's model: the kernel density, unless the config asks for another surrogate
            raw["general"] = {"surrogate": "kde", **general}
        self.config: PlannerConfig = load_config(raw, base_dir)
        self.planner = Planner(self.config, known_constraints)
        self.known_constraints = known_constraints
        self.planner.feasible_fraction  # noqa: B018 - estimated now, as Gryffin does, so a bad domain fails here
        self.iter_counter = 0  # recommend() calls so far; each call draws anew, as Gryffin's NumPy state advances
        self.sampling_strategies: np.ndarray | None = None  # of the last recommend()
        self.num_batches: int | None = None  # of the last recommend()
        self._last: tuple[list[dict[str, Any]], int] | None = None  # observations and draw of the last model
        self._models: tuple[Planner, Surrogates] | None = None

    @property
    def frac_feas(self) -> float:
        """The feasible fraction of the domain under the known constraints (1.0 without any)."""
        return self.planner.feasible_fraction.value

    # ---- proposals -------------------------------------------------------------------------------------------
    def _observations(self, observations: Sequence[Mapping[str, Any]] | None) -> list[dict[str, Any]]:
        """Gryffin's observation dicts, keeping the parameters and objectives (Gryffin ignores any other key). Every
        objective must be there (NaN or None for a failed experiment), as Gryffin requires."""
        if observations is None:
            return []
        if isinstance(observations, Mapping):
            raise ObservationError("observations must be a list of dicts (one per experiment), got one dict")
        objectives = [o.name for o in self.planner.objectives]
        keep = set(self.planner.parameter_names) | set(objectives)
        out = []
        for i, item in enumerate(observations):
            if not isinstance(item, Mapping):
                raise ObservationError(f"observations[{i}] must be a dict, got {type(item).__name__}")
            missing = [name for name in objectives if name not in item]
            if missing:
                raise ObservationError(f"observations[{i}]: missing objective(s) {missing} (NaN or None for a failed "
                                       "experiment)")
            # 0-d arrays (np.squeeze of a measurement, as Olympus reports them) are plain numbers to Gryffin, and
            # NaN is Gryffin's word for a failed experiment: None here
            row = {k: (v.item() if isinstance(v, np.ndarray) and v.ndim == 0 else v) for k, v in item.items()
                   if k in keep}
            out.append({k: (None if k in objectives and _is_nan(v) else v) for k, v in row.items()})
        return out

    def recommend(self, observations: Sequence[Mapping[str, Any]] | None = None,
                  sampling_strategies: Sequence[float] | None = None, num_batches: int | None = None,
                  as_array: bool = False) -> list[dict[str, Any]] | np.ndarray:
        """The next experiments for these observations: `num_batches` (default general.batches) batches of one
        proposal per sampling strategy, batch by batch. `sampling_strategies` (s: +1 exploit, -1 explore; any
        number of them) replace the config's `sampling_strategies` for this call. Without observations the
        proposals are random (feasible). `as_array`: an (n, D) array instead of dicts, continuous parameters in
        their units and discrete/categorical ones as the index of their option, as in Gryffin."""
        rows = self._observations(observations)
        if sampling_strategies is None:
            strategies = self.planner.strategy_values()
        else:
            strategies = np.atleast_1d(np.asarray(sampling_strategies, dtype=float))
        params = self.planner.recommend(rows, sampling_strategies, num_batches, draw=self.iter_counter)
        self.sampling_strategies = strategies
        self.num_batches = self.config.general.batches if num_batches is None else int(num_batches)
        self._remember(rows)
        self.iter_counter += 1
        return self._as_array(params) if as_array else params

    def build_surrogate(self, observations: Sequence[Mapping[str, Any]] | None = None) -> None:
        """Build the models of these observations for the read-outs, without proposing anything."""
        rows = self._observations(observations)
        if not rows:
            LOGGER.warning("no observations: no surrogate model can be built")
            return
        if self.sampling_strategies is None:
            self.sampling_strategies = self.planner.strategy_values()
        self._remember(rows)

    def _remember(self, rows: list[dict[str, Any]]) -> None:
        self._last, self._models = ((rows, self.iter_counter) if rows else None), None

    def _as_array(self, params: list[dict[str, Any]]) -> np.ndarray:
        space = self.config.space
        X = space.to_internal(params)
        for d in space.cont_idx:
            X[:, d] = [float(p[space.names[d]]) for p in params]
        return X

    # ---- read-outs of the last model -------------------------------------------------------------------------
    def _surrogates(self) -> tuple[Planner, Surrogates]:
        """The planner and models of the last recommend()/build_surrogate() call with observations (the same models
        that call proposed from)."""
        if self._last is None:
            raise GryffinRosError("no model yet: call recommend() or build_surrogate() with observations first")
        if self._models is None:
            rows, draw = self._last
            planner = self.planner.with_observations(rows, draw)
            self._models = (planner, planner.surrogates())
        return self._models

    def _points(self, planner: Planner, params: Any) -> tuple[torch.Tensor, torch.Tensor]:
        return split(planner.space, planner.space.to_internal(_rows(params)))

    def get_regression_surrogate(self, params: Any) -> np.ndarray:
        """The kernel regression of the last model at `params` (list of dicts or a DataFrame): with one objective
        in its units (the observed range; the objective transform undone), with several Chimera's merit in [0, 1]
        (0 best)."""
        planner, models = self._surrogates()
        if models.density is None:
            raise ObservationError("no successful observation yet: the regression surrogate needs at least one")
        with torch.no_grad():
            merit = models.density.regression(*self._points(planner, params)).numpy()
        merit = OBJ_TRANSFORMS[self.config.general.obj_transform][1](np.clip(merit, 0.0, 1.0))
        if len(planner.objectives) > 1:
            return merit
        objective = planner.objectives[0]
        y = np.array([o.objectives[objective.name] for o in models.successful])
        span = y.max() - y.min()
        return y.max() - merit * span if objective.goal == "max" else y.min() + merit * span

    def get_feasibility_surrogate(self, params: Any, threshold: float | None = None) -> np.ndarray:
        """P(feasible) at `params` from the failed experiments (1.0 everywhere before any failed); with `threshold`,
        whether it exceeds it."""
        planner, models = self._surrogates()
        X = planner.space.to_internal(_rows(params))
        p = models.feasibility.probability(X) if models.feasibility is not None else np.ones(len(X))
        return p if threshold is None else p > threshold

    def get_kernel_density_estimate(self, params: Any, separate_kwn_ukwn: bool = False) -> np.ndarray:
        """The kernel density of all observed experiments at `params`, in internal units (continuous dimensions
        rescaled to [0, 1], finite ones per option), with the planner's kernels: (M,), or with `separate_kwn_ukwn`
        (M, 2) = the parts of the successful and of the failed experiments (the two sum to the density)."""
        planner, _ = self._surrogates()
        observed = planner.observed_points()
        failed = np.array([o.failed for o in planner.observations])
        general = self.config.general
        kde = KernelDensity(planner.space, observed, failed.astype(float), planner.feasible_fraction.value,
                            torch.Generator().manual_seed(planner.seed), spacing_scaled=planner.spacing_kernels,
                            spacing_factor=SPACING_FACTOR, temperature_scale=general.concrete_temperature)
        with torch.no_grad():
            log_p = kde.log_kernels(*self._points(planner, params)) - np.log(kde.n_kernels)
        ok = torch.as_tensor(~failed[kde.origin])
        parts = [torch.logsumexp(log_p[:, mask], dim=1).exp().numpy() if mask.any() else np.zeros(len(log_p))
                 for mask in (ok, ~ok)]
        return np.stack(parts, axis=1) if separate_kwn_ukwn else parts[0] + parts[1]

    def get_acquisition(self, X: Any) -> dict[float, np.ndarray]:
        """The kernel acquisition of the last model at `X` for each sampling strategy of the last call, by strategy
        value (before it is combined with P(feasible) of failed experiments)."""
        planner, models = self._surrogates()
        if models.density is None:
            raise ObservationError("no successful observation yet: the acquisition needs at least one")
        points = planner.space.to_internal(_rows(X))
        return {float(s): Acquisition(models.density, float(s)).evaluate(points) for s in self.sampling_strategies}

    def _descriptor_summary(self, target: str) -> dict[str, Any]:
        planner, _ = self._surrogates()
        return {name: parts[target] for name, parts in planner.descriptor_summary().items() if target in parts}

    def get_descriptor_summary_regression(self) -> dict[str, Any]:
        """What dynamic descriptors (general.auto_desc_gen) learned for the objective model, per categorical
        parameter: the relevance of each given descriptor and the correlations of the generated ones (our format)."""
        return self._descriptor_summary("objective")

    def get_descriptor_summary_feasibility(self) -> dict[str, Any]:
        """As get_descriptor_summary_regression, for the model of failed experiments."""
        return self._descriptor_summary("feasibility")

    def read_db(self, outfile: str = "database.csv", verbose: bool = True) -> None:
        """Not available: Gryffin's database is not kept here."""
        raise UnsupportedError(
            "read_db: there is no Gryffin database here (general.save_database has no effect); the observations are "
            "the list you pass to recommend(), so write them out yourself (e.g. csv.DictWriter), or run the campaign "
            "with gryffin_ros.planner.Planner and gryffin_ros.storage.CampaignStore, exported by "
            "`gryffin-ros export STORE --csv FILE`")


def _is_nan(value: Any) -> bool:
    return isinstance(value, (float, np.floating)) and bool(np.isnan(value))
