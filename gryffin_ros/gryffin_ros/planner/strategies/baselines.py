"""Baseline strategies behind the Planner interface, for benchmarks: Random (rejection-sampled uniform search) and
Genetic (a steady-state DEAP genetic algorithm directly on the objective, with the same boundary projection).
"""

from __future__ import annotations

import numpy as np
from deap import tools

from ..optimizers.genetic import (
    CROSSOVER_PROB,
    MUTATION_PROB,
    TOURNAMENT_SIZE,
    crossover,
    mutate,
    project_to_feasible,
    seeded_python_random,
    to_individuals,
)
from .base import BasePlanner
from .selection import duplicates


class Random(BasePlanner):
    """Uniform feasible proposals, never repeating a point of a finite space."""

    def _propose(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, list[float | None], dict]:
        avoid = np.concatenate([self.observed_points(), self.pending_points()])
        return self.random_points(n, rng, avoid), [None] * n, {}


class Genetic(BasePlanner):
    """Steady-state genetic search on the objective: the first `population_size` experiments are random; after
    that, parents come by tournament from the best `population_size` successful observations."""

    population_size = 20

    def _propose(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, list[float | None], dict]:
        chosen = np.concatenate([self.observed_points(), self.pending_points()])
        successful = [o for o in self.observations if not o.failed]
        if len(self.observations) + len(self.pending) < self.population_size or len(successful) < 2:
            return self.random_points(n, rng, chosen), [None] * n, {}
        merits = self.merits(successful)
        order = np.argsort(merits)[:self.population_size]
        population = to_individuals(self._internal([successful[i].params for i in order]), merits[order])
        points = []
        with seeded_python_random(rng):
            for _ in range(n):
                x = self._child(population, chosen, rng)
                chosen = np.concatenate([chosen, x[None]])
                points.append(x)
        return np.array(points), [None] * n, {}

    def _child(self, population: list, chosen: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        space = self.space
        for _ in range(50):
            a, b = (np.array(p) for p in tools.selTournament(population, 2, TOURNAMENT_SIZE))
            child = a.copy()
            if rng.random() < CROSSOVER_PROB:
                first, second = list(a), list(b)
                crossover(space, first, second)
                child = project_to_feasible(self.constraints, space.clip(np.array([first])), a[None])[0]
            if rng.random() < MUTATION_PROB or duplicates(space, child[None], chosen)[0]:
                child = project_to_feasible(self.constraints, mutate(space, child[None], rng), child[None])[0]
            if not duplicates(space, child[None], chosen)[0]:
                return child
        return self.random_points(1, rng, chosen)[0]
