"""The flow-reactor emulator of the paper: a Bayesian neural network (3 -> 64 -> 64 -> 64 -> 4, ReLU, softmax) trained
on Walker et al.'s 600 experiments, predicting the mole fractions X0..X3 of C60 and its mono-, bis- and tris-adducts
from the C60 flow F_C, the sultine flow F_S (uL/min) and the temperature T (degC). One experiment is one stochastic
forward pass (weights drawn from their mean-field Gaussians), so repeated experiments scatter like real ones.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from typing import Any

import numpy as np

from ..planner.constraints import Expression, NamedConstraint
from ..planner.errors import ConfigError

LAYERS = ("blinear1", "blinear2", "blinear3", "blinear4")
OUTPUTS = ("X0", "X1", "X2", "X3", "X1_X2", "cost")
# Reagent cost per uL of each stream, in $ (paper SI): C60 solution and sultine solution.
C60_COST, SULTINE_COST = 168.8e-6, 2.674e-6


@dataclass(frozen=True)
class FlowReactorResult:
    """One emulated experiment: mole fractions X0..X3, the combined yield X1 + X2 and the reagent cost in $/min."""

    x0: float
    x1: float
    x2: float
    x3: float
    cost: float

    @property
    def yield_x1_x2(self) -> float:
        return self.x1 + self.x2

    def as_dict(self) -> dict[str, float]:
        return {"X0": self.x0, "X1": self.x1, "X2": self.x2, "X3": self.x3, "X1_X2": self.yield_x1_x2,
                "cost": self.cost}


def reagent_cost(c60_flow: float, sultine_flow: float) -> float:
    """$/min of reagents at the given flows (uL/min)."""
    return C60_COST * c60_flow + SULTINE_COST * sultine_flow


def _softplus(x: np.ndarray) -> np.ndarray:
    return np.logaddexp(0.0, x)


class FlowReactorEmulator:
    outputs = OUTPUTS

    def __init__(self, seed: int | None = None, parameters: tuple[str, str, str] = ("F_C", "F_S", "T")):
        self.parameters = tuple(parameters)
        data = resources.files("gryffin_ros.emulators").joinpath("data")
        with data.joinpath("fullerenes_weights.npz").open("rb") as handle:
            weights = dict(np.load(handle))
        self._layers = []
        for name in LAYERS:
            self._layers.append((weights[f"{name}__mu_weight"], _softplus(weights[f"{name}__rho_weight"]),
                                 weights[f"{name}__mu_bias"], _softplus(weights[f"{name}__rho_bias"])))
        scaler = json.loads(data.joinpath("fullerenes_feature_scaler.json").read_text())
        self._data_min = np.asarray(scaler["data_min_"], dtype=float)
        self._data_range = np.asarray(scaler["data_range_"], dtype=float)
        self.rng = np.random.default_rng(seed)

    def predict(self, inputs: np.ndarray, passes: int = 1) -> np.ndarray:
        """inputs (M, 3) = [F_C, F_S, T] in users' units -> (passes, M, 4) mole fractions, one weight draw per pass."""
        x = (np.atleast_2d(np.asarray(inputs, dtype=float)) - self._data_min) / self._data_range
        h = np.broadcast_to(x, (passes, *x.shape))
        for i, (w_mu, w_sd, b_mu, b_sd) in enumerate(self._layers):
            w = w_mu + w_sd * self.rng.standard_normal((passes, *w_mu.shape))
            b = b_mu + b_sd * self.rng.standard_normal((passes, *b_mu.shape))
            h = np.einsum("pmi,poi->pmo", h, w) + b[:, None, :]
            if i < len(self._layers) - 1:
                h = np.maximum(h, 0.0)
        h = h - h.max(axis=-1, keepdims=True)
        e = np.exp(h)
        return e / e.sum(axis=-1, keepdims=True)

    def run(self, c60_flow: float, sultine_flow: float, temperature: float) -> FlowReactorResult:
        """One experiment: a single stochastic pass."""
        x = self.predict(np.array([[c60_flow, sultine_flow, temperature]]))[0, 0]
        return FlowReactorResult(*map(float, x), cost=reagent_cost(c60_flow, sultine_flow))

    def measure(self, params: Mapping[str, float]) -> dict[str, float]:
        """One experiment from a parameter dict (names in `parameters`): every output."""
        return self.run(*(float(params[n]) for n in self.parameters)).as_dict()


# ---- the reactor's known constraints, registered as the constraint plugin `flow_reactor` (setup.py) -----------
def flow_reactor_constraint(options: Mapping[str, Any], parameters: Mapping[str, Any]) -> NamedConstraint:
    """Flow limits of the C60 reactor: min_total < F_C + F_S < max_total, and each flow below ratio x the other."""
    allowed = {"min_total", "max_total", "ratio", "c60_flow", "sultine_flow"}
    unknown = set(options) - allowed
    if unknown:
        raise ConfigError(f"flow_reactor constraint: unknown option(s) {sorted(unknown)}; allowed {sorted(allowed)}")
    fc, fs = options.get("c60_flow", "F_C"), options.get("sultine_flow", "F_S")
    for key, name in (("c60_flow", fc), ("sultine_flow", fs)):
        if not isinstance(name, str) or name not in parameters or parameters[name].kind != "continuous":
            continuous = sorted(n for n, p in parameters.items() if p.kind == "continuous")
            raise ConfigError(f"flow_reactor constraint: '{key}' must name a continuous parameter (one of "
                              f"{continuous}), got {name!r}")
    if fc == fs:
        raise ConfigError(f"flow_reactor constraint: 'c60_flow' and 'sultine_flow' must be two parameters, both are "
                          f"{fc!r}")
    low, high, ratio = options.get("min_total", 30.0), options.get("max_total", 310.0), options.get("ratio", 2.0)
    for key, value in (("min_total", low), ("max_total", high), ("ratio", ratio)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ConfigError(f"flow_reactor constraint: '{key}' must be a finite number, got {value!r}")
    if not low < high:
        raise ConfigError(f"flow_reactor constraint: min_total ({low}) must be below max_total ({high})")
    text = f"{low!r} < {fc} + {fs} < {high!r} and {fc} < {ratio!r} * {fs} and {fs} < {ratio!r} * {fc}"
    expression = Expression(text, parameters, parameters)
    return NamedConstraint(f"flow_reactor({text})", expression, expression.evaluate)
