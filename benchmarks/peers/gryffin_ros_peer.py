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


def config(task, surrogate: str | None, molecules: bool, names: dict[str, list[str]]) -> dict:
    """The planner's config of a harness task; `names`: option_names_of."""
    parameters = []
    for p in task.params:
        if molecules and getattr(p, "smiles", None):
            parameters.append({"name": p.name, "type": "categorical",
                               "options": dict(zip(names[p.name], p.smiles)),
                               "molecular_descriptors": "default"})
        elif getattr(p, "categorical", False):
            parameter = {"name": p.name, "type": "categorical", "options": names[p.name]}
            if any(p.descriptors):
                parameter["descriptors"] = dict(zip(names[p.name], p.descriptors))
            parameters.append(parameter)
        elif p.kind == "int":
            parameters.append({"name": p.name, "type": "discrete", "options": list(range(p.low, p.high + 1))})
        else:
            parameters.append({"name": p.name, "type": "continuous", "low": p.low, "high": p.high})
    return {"name": f"peer_{task.name}", "parameters": parameters, "objectives": [{"name": "y", "goal": "min"}],
            "general": {"surrogate": surrogate} if surrogate else {}}


def option_names_of(task, seed: int) -> dict[str, list[str]]:
    """Each categorical parameter's option names in the run of `seed` (a molecule task's labels, else its options),
    by parameter name; made once per run: the known-constraint callable converts every point the planner checks."""
    return {p.name: p.labels(seed) if hasattr(p, "labels") else list(p.options) for p in task.params
            if getattr(p, "categorical", False)}


def to_planner(task, x: list, names: dict[str, list[str]]) -> dict:
    """A harness point (categorical options as indices) -> the planner's parameters; `names`: option_names_of."""
    return {p.name: (names[p.name][int(v)] if p.name in names else v) for p, v in zip(task.params, x)}


def from_planner(task, params: dict, index: dict[str, dict[str, int]]) -> list:
    """The planner's parameters -> a harness point; `index`: option name -> its index, by parameter name."""
    return [(index[p.name][params[p.name]] if p.name in index else params[p.name]) for p in task.params]


class Adapter:
    surrogate = "kde"
    molecules = False

    def __init__(self, task, seed):
        self.names = [p.name for p in task.params]
        self.task = task
        self.option_names = option_names_of(task, seed)
        self.option_index = {name: {o: i for i, o in enumerate(options)} for name, options in self.option_names.items()}
        self.planner = Planner(config(task, self.surrogate, self.molecules, self.option_names),
                               known_constraints=lambda params: task.feasible(from_planner(task, params,
                                                                                           self.option_index)),
                               seed=seed)
        self.asked: str | None = None  # experiment_id of the proposal the harness is evaluating
        self.choices: dict[str, int] = {}

    def ask(self) -> list:
        proposal = self.planner.ask(1)[0]
        self.asked = proposal.experiment_id
        surrogate = proposal.meta.get("surrogate", "random")
        self.choices[surrogate] = self.choices.get(surrogate, 0) + 1
        return from_planner(self.task, proposal.params, self.option_index)

    def tell(self, xs, ys) -> None:
        for x, y in zip(xs, ys):
            if y is None:  # a violation (the harness counts it); not an observation of the objective
                continue
            experiment_id = self.asked if len(xs) == 1 else None
            self.planner.tell({"experiment_id": experiment_id, "params": to_planner(self.task, x, self.option_names),
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
