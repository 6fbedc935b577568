"""What the dashboard shows, computed from a campaign store (read-only) and its config: plain JSON-ready data, no
web code here. The best-so-far traces are `planner.merit.best_so_far` (the campaign's own merit, Chimera
included); the feasible region is computed from the constraints the planner uses."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..planner import Planner
from ..planner.chimera import hierarchy, tolerance_line
from ..planner.config import load_config, units_of
from ..planner.errors import ConfigError, GryffinRosError
from ..planner.merit import best_so_far
from ..planner.molecules import MoleculeCache, draw_svg, smiles_of
from ..storage import CampaignStore

# The two-parameter view: a grid of GRID x GRID cells (continuous axes; one cell per option of a finite one), each
# judged at the same random values of the other parameters (the shade is the feasible share of them; 1 where the
# constraints do not involve the others). The same completions in every cell: two cells whose constraints agree get
# the same share, not two noisy estimates of it. SAMPLES judgements in all, at least COMPLETIONS and at most
# MAX_COMPLETIONS per cell: a 40 x 40 grid gets 16 per cell, three options against 40 values 213 (standard error of
# a share near 0.6 below 0.04), three by four options 512.
GRID = 40
COMPLETIONS = 16
SAMPLES = GRID * GRID * COMPLETIONS
MAX_COMPLETIONS = 512


class CannotDraw(GryffinRosError):
    """A molecule cannot be drawn here (RDKit is not installed): the page shows its SMILES alone."""


def _number(value: Any) -> Any:
    """JSON has no NaN or infinity: those become null."""
    return None if isinstance(value, float) and not math.isfinite(value) else value


class CampaignView:
    """The data of one store; `config_dir` is where relative file names of the config (lookup tables) are found."""

    def __init__(self, store_path: str | Path, config_dir: str | Path | None = None):
        self.store_path = Path(store_path)
        self.store = CampaignStore.open_existing(self.store_path)
        raw = self.store.config
        self.raw = raw
        # RDKit's values for SMILES options, as the campaign stored them: the page needs RDKit only to draw molecules
        molecules = MoleculeCache(self.store.molecule_values())
        # judging needs only the objectives: it always works, whatever the constraints refer to
        self.config = load_config({**raw, "constraints": []}, molecule_cache=molecules)
        self.smiles = smiles_of(raw)
        self._drawings: dict[tuple[str, str], str] = {}
        base = Path(config_dir) if config_dir is not None else self.store_path.resolve().parent
        try:
            self.planner: Planner | None = Planner(load_config(raw, base, molecules), seed=0)
            self.constraint_error: str | None = None
        except Exception as exc:  # noqa: BLE001 - shown on the page instead of the feasible region
            self.planner, self.constraint_error = None, f"{type(exc).__name__}: {exc}"
        self._cache: tuple[tuple, dict] | None = None
        self._regions: dict[tuple[str, str], dict] = {}  # the constraints do not change: each pair computed once

    def close(self) -> None:
        self.store.close()

    def version(self) -> tuple[int, int, int]:
        """Changes whenever the store gains an observation, a proposal or a rejection."""
        return self.store.counts()

    def campaign(self) -> dict[str, Any]:
        version = self.version()
        if self._cache is not None and self._cache[0] == version:
            return self._cache[1]
        data = self._campaign(version)
        self._cache = (version, data)
        return data

    def _campaign(self, version: tuple[int, int, int]) -> dict[str, Any]:
        config, units = self.config, units_of(self.raw)
        observations = self.store.observations()
        proposals = {p.experiment_id: p for p in self.store.proposals()}
        reported = {o.experiment_id for o in observations}
        experiments = []
        for seq, o in enumerate(observations, start=1):
            proposal = proposals.get(o.experiment_id)
            experiments.append({
                "seq": seq, "experiment_id": o.experiment_id, "params": o.params,
                "objectives": {k: _number(v) for k, v in o.objectives.items()}, "failed": o.failed,
                "strategy": None if proposal is None else proposal.strategy,
                "surrogate": None if proposal is None else proposal.meta.get("surrogate"),
            })
        bests = best_so_far(self.config, observations)
        last = bests[-1] if bests else None  # the best experiment now: its conditions head the page
        best_experiment = None if last is None else next((
            {"seq": e["seq"], "experiment_id": e["experiment_id"], "params": e["params"],
             "objectives": e["objectives"]} for e in experiments if e["experiment_id"] == last.experiment_id), None)
        best, tolerances = {}, {}
        for objective in config.objectives:
            values = np.array([np.nan if o.objectives[objective.name] is None else o.objectives[objective.name]
                               for o in observations], dtype=float)
            best[objective.name] = [None if b is None else _number(b.objectives[objective.name]) for b in bests]
            line = tolerance_line(objective, values) if len(config.objectives) > 1 else None
            tolerances[objective.name] = None if line is None else float(line)
        pending = [{"experiment_id": p.experiment_id, "params": p.params, "strategy": p.strategy,
                    "surrogate": p.meta.get("surrogate")}
                   for p in proposals.values() if p.experiment_id not in reported]
        modelled = self.planner.space.names if self.planner is not None else ()
        return {
            "campaign": config.name, "version": list(version),
            "parameters": [{"name": p.name, "kind": p.kind, "units": units.get(p.name, ""),
                            "options": list(getattr(p, "options", ()) or ()) or None,
                            "low": getattr(p, "low", None), "high": getattr(p, "high", None),
                            "smiles": self.smiles.get(p.name)}
                           for p in config.space.parameters],
            "objectives": [{"name": o.name, "goal": o.goal, "units": units.get(o.name, ""),
                            "tolerance": o.tolerance, "absolute": o.absolute} for o in config.objectives],
            "hierarchy": hierarchy(config) if len(config.objectives) > 1 else None,
            "experiments": experiments, "best": best, "best_experiment": best_experiment, "tolerances": tolerances,
            "pending": pending,
            "rejected": self.store.rejections(),
            "axes": list(modelled),
            "constraint_error": self.constraint_error,
        }

    def molecule_svg(self, parameter: str, option: str) -> str:
        """A drawing (SVG) of an option of a parameter given as SMILES; only the config's molecules are drawn.
        Raises ValueError for anything else, CannotDraw without RDKit."""
        smiles = self.smiles.get(parameter, {}).get(option)
        if smiles is None:
            raise ValueError(f"'{option}' is no molecule of '{parameter}'; molecules: "
                             f"{ {name: sorted(options) for name, options in self.smiles.items()} }")
        if (parameter, option) not in self._drawings:
            try:
                self._drawings[(parameter, option)] = draw_svg(smiles)
            except ConfigError as exc:
                raise CannotDraw(str(exc)) from None
        return self._drawings[(parameter, option)]

    def feasible(self, x: str, y: str) -> dict[str, Any]:
        """The feasible share of each cell of the (x, y) plane, over the other parameters' domain (cached)."""
        if (x, y) not in self._regions:
            self._regions[(x, y)] = self._feasible(x, y)
        return self._regions[(x, y)]

    def _feasible(self, x: str, y: str) -> dict[str, Any]:
        if self.planner is None:
            raise ValueError(f"the constraints could not be loaded: {self.constraint_error}")
        space = self.planner.space
        if x not in space.names or y not in space.names or x == y:
            raise ValueError(f"choose two different parameters among {list(space.names)}")
        dx, dy = space.names.index(x), space.names.index(y)

        def axis(d: int) -> tuple[np.ndarray, list]:
            p = space.parameters[d]
            if p.kind == "continuous":
                u = (np.arange(GRID) + 0.5) / GRID
                return u, (p.low + u * p.span).tolist()
            return np.arange(len(p.options), dtype=float), list(p.options)

        (ux, vx), (uy, vy) = axis(dx), axis(dy)
        cells = len(ux) * len(uy)
        per_cell = int(min(MAX_COMPLETIONS, max(COMPLETIONS, SAMPLES // cells)))
        completions = space.sample(np.random.default_rng(0), per_cell)
        X = np.tile(completions, (cells, 1))
        X[:, dx] = np.repeat(np.tile(ux, len(uy)), per_cell)
        X[:, dy] = np.repeat(np.repeat(uy, len(ux)), per_cell)
        share = self.planner.constraints.feasible(X).reshape(len(uy), len(ux), per_cell).mean(axis=2)
        return {"x": {"name": x, "values": vx}, "y": {"name": y, "values": vy}, "share": share.round(3).tolist()}
