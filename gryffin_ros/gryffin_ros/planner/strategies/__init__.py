"""Strategies behind the ask/tell interface of `BasePlanner`: the paper's constrained kernel-density `Planner`
(`gryffin`), and the `Random` and `Genetic` baselines of the benchmarks. STRATEGIES names them (planner states
record which one saved them)."""

from .base import BasePlanner
from .baselines import Genetic, Random
from .gryffin import Planner

STRATEGIES: dict[str, type[BasePlanner]] = {"Planner": Planner, "Random": Random, "Genetic": Genetic}

__all__ = ["STRATEGIES", "BasePlanner", "Genetic", "Planner", "Random"]
