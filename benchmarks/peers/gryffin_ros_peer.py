"""The peer harness's adapter (../shared/peers, README "Our planner") around gryffin_ros's Planner, one module per
surrogate: peer_gryffin_ros_kde, peer_gryffin_ros_gp and peer_gryffin_ros_auto each call `adapter(surrogate)`.

Floats become continuous parameters, ints discrete ones (ordered options low..high); the task's constraint is the
planner's known constraint. Each proposal is reported back under its experiment_id, so nothing stays pending.
"""

from __future__ import annotations

import gryffin_ros
from gryffin_ros.planner import Planner

DEFAULT_SEEDS = {"branin": range(10), "slope": range(10), "reactor": range(3)}


def config(task, surrogate: str) -> dict:
    parameters = []
    for p in task.params:
        if p.kind == "int":
            parameters.append({"name": p.name, "type": "discrete", "options": list(range(p.low, p.high + 1))})
        else:
            parameters.append({"name": p.name, "type": "continuous", "low": p.low, "high": p.high})
    return {"name": f"peer_{task.name}", "parameters": parameters, "objectives": [{"name": "y", "goal": "min"}],
            "general": {"surrogate": surrogate}}


class Adapter:
    surrogate = "kde"

    def __init__(self, task, seed):
        self.names = [p.name for p in task.params]
        self.task = task
        self.planner = Planner(config(task, self.surrogate),
                               known_constraints=lambda params: task.feasible([params[n] for n in self.names]),
                               seed=seed)
        self.asked: str | None = None  # experiment_id of the proposal the harness is evaluating
        self.choices: dict[str, int] = {}

    def ask(self) -> list:
        proposal = self.planner.ask(1)[0]
        self.asked = proposal.experiment_id
        surrogate = proposal.meta.get("surrogate", "random")
        self.choices[surrogate] = self.choices.get(surrogate, 0) + 1
        return [proposal.params[n] for n in self.names]

    def tell(self, xs, ys) -> None:
        for x, y in zip(xs, ys):
            if y is None:  # a violation (the harness counts it); not an observation of the objective
                continue
            experiment_id = self.asked if len(xs) == 1 else None
            self.planner.tell({"experiment_id": experiment_id, "params": dict(zip(self.names, x)),
                               "objectives": {"y": float(y)}})
        self.asked = None

    def info(self) -> dict:
        return {f"chose_{name}": count for name, count in self.choices.items()}


def adapter(surrogate: str) -> tuple[str, str, dict, type]:
    """(PEER, VERSION, DEFAULT_SEEDS, Optimizer) for the harness."""
    optimizer = type(f"Optimizer_{surrogate}", (Adapter,), {"surrogate": surrogate})
    return f"gryffin_ros_{surrogate}", gryffin_ros.__version__, DEFAULT_SEEDS, optimizer
