"""The redox-flow-battery emulator: DFT values of the 1408 benzothiadiazole candidates (Olympus `redoxmers` data set)
looked up by their four R-groups, optionally with the per-candidate Gaussian noise scales published with them."""

from __future__ import annotations

import csv
from collections.abc import Mapping
from importlib import resources

import numpy as np

PARAMETERS = ("r1_label", "r3_label", "r4_label", "r5_label")
OUTPUTS = ("abs_lam_diff", "ered", "gsol")


class RedoxEmulator:
    parameters = PARAMETERS
    outputs = OUTPUTS

    def __init__(self, noise: bool = False, seed: int | None = None):
        self.noise = noise
        self.rng = np.random.default_rng(seed)
        self._table: dict[tuple[str, ...], tuple[np.ndarray, np.ndarray]] = {}
        path = resources.files("gryffin_ros.emulators").joinpath("data/redox_candidates.csv")
        with path.open() as handle:
            for row in csv.DictReader(handle):
                key = tuple(row[p] for p in PARAMETERS)
                self._table[key] = (np.array([float(row[o]) for o in OUTPUTS]),
                                    np.array([float(row[f"{o}_std"]) for o in OUTPUTS]))

    def measure(self, params: Mapping[str, str]) -> dict[str, float]:
        """|lambda_abs - 375 nm| (nm), E_red (V) and G_solv (eV) of one candidate (KeyError for an unknown one)."""
        mean, std = self._table[tuple(params[p] for p in PARAMETERS)]
        values = mean + (self.rng.normal(0.0, std) if self.noise else 0.0)
        return dict(zip(OUTPUTS, map(float, values)))
