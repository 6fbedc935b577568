"""The peer harness's adapter (../shared/peers, README "Our planner") around gryffin_ros's Planner, one module per
surrogate: peer_gryffin_ros_default (no `surrogate` key: what a user gets), peer_gryffin_ros_kde, _gp and _auto each
call `adapter(surrogate)`.

Floats become continuous parameters, ints discrete ones (ordered options low..high), categorical parameters
(`problems.CatParam`) categorical ones with their descriptors; with `molecules` (peer_gryffin_ros_molecules), a
categorical parameter that carries `smiles` (benchmarks/molecule_tasks.py) has its options given as SMILES, and RDKit
computes their default descriptors. The task's constraint is the planner's known constraint. Each proposal is
reported back under its experiment_id, so nothing stays pending.
"""

from __future__ import annotations

import gryffin_ros
from gryffin_ros.planner import Planner

DEFAULT_SEEDS = {"branin": range(10), "slope": range(10), "reactor": range(3)}


def option_names(p, seed: int) -> list[str]:
    """The names of a categorical parameter's options in the run of `seed` (a molecule task's labels)."""
    return p.labels(seed) if hasattr(p, "labels") else list(p.options)


def config(task, surrogate: str | None, molecules: bool = False, seed: int = 0) -> dict:
    parameters = []
    for p in task.params:
        if molecules and getattr(p, "smiles", None):
            parameters.append({"name": p.name, "type": "categorical",
                               "options": dict(zip(option_names(p, seed), p.smiles)),
                               "molecular_descriptors": "default"})
        elif getattr(p, "categorical", False):
            names = option_names(p, seed)
            parameter = {"name": p.name, "type": "categorical", "options": names}
            if any(p.descriptors):
                parameter["descriptors"] = dict(zip(names, p.descriptors))
            parameters.append(parameter)
        elif p.kind == "int":
            parameters.append({"name": p.name, "type": "discrete", "options": list(range(p.low, p.high + 1))})
        else:
            parameters.append({"name": p.name, "type": "continuous", "low": p.low, "high": p.high})
    return {"name": f"peer_{task.name}", "parameters": parameters, "objectives": [{"name": "y", "goal": "min"}],
            "general": {"surrogate": surrogate} if surrogate else {}}


def to_planner(task, x: list, seed: int = 0) -> dict:
    """A harness point (categorical options as indices) -> the planner's parameters."""
    return {p.name: (option_names(p, seed)[int(v)] if getattr(p, "categorical", False) else v)
            for p, v in zip(task.params, x)}


def from_planner(task, params: dict, seed: int = 0) -> list:
    return [(option_names(p, seed).index(params[p.name]) if getattr(p, "categorical", False) else params[p.name])
            for p in task.params]


class Adapter:
    surrogate = "kde"
    molecules = False

    def __init__(self, task, seed):
        self.names = [p.name for p in task.params]
        self.task, self.seed = task, seed
        self.planner = Planner(config(task, self.surrogate, self.molecules, seed),
                               known_constraints=lambda params: task.feasible(from_planner(task, params, seed)),
                               seed=seed)
        self.asked: str | None = None  # experiment_id of the proposal the harness is evaluating
        self.choices: dict[str, int] = {}

    def ask(self) -> list:
        proposal = self.planner.ask(1)[0]
        self.asked = proposal.experiment_id
        surrogate = proposal.meta.get("surrogate", "random")
        self.choices[surrogate] = self.choices.get(surrogate, 0) + 1
        return from_planner(self.task, proposal.params, self.seed)

    def tell(self, xs, ys) -> None:
        for x, y in zip(xs, ys):
            if y is None:  # a violation (the harness counts it); not an observation of the objective
                continue
            experiment_id = self.asked if len(xs) == 1 else None
            self.planner.tell({"experiment_id": experiment_id, "params": to_planner(self.task, x, self.seed),
                               "objectives": {"y": float(y)}})
        self.asked = None

    def info(self) -> dict:
        return {f"chose_{name}": count for name, count in self.choices.items()}


def adapter(surrogate: str | None, molecules: bool = False) -> tuple[str, str, dict, type]:
    """(PEER, VERSION, DEFAULT_SEEDS, Optimizer) for the harness; surrogate None: the planner's default; molecules:
    SMILES options with RDKit's default descriptors where the task has them."""
    name = "molecules" if molecules else surrogate or "default"
    optimizer = type(f"Optimizer_{name}", (Adapter,), {"surrogate": surrogate, "molecules": molecules})
    return f"gryffin_ros_{name}", gryffin_ros.__version__, DEFAULT_SEEDS, optimizer
