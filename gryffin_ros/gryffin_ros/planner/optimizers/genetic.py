"""The genetic acquisition optimizer (DEAP) and the variation operators it shares with the Genetic baseline.

Tournament selection (size 3), 5 % elitism, crossover p 0.5 (uniform for 2 genes, two-point for 3 or more),
mutation p 0.4 with per-gene p 0.2, at most 10 generations, early stop when every gene spans < 10 % of its range.
Infeasible children are projected onto the feasibility boundary (paper SI: categories from the parent, bisection
towards the feasible parent until ||delta||_inf < 1 % of the range, then the child's own categories if feasible).
"""

from __future__ import annotations

import random
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
from deap import base, creator, tools

from ..acquisition.kernel import Acquisition
from ..constraints import KnownConstraints, line_limits
from ..reporting import report
from ..space import SearchSpace

TOURNAMENT_SIZE = 3
ELITE_FRACTION = 0.05
CROSSOVER_PROB = 0.5
MUTATION_PROB = 0.4
GENE_MUTATION_PROB = 0.2
MUTATION_SCALE = 0.1
MAX_GENERATIONS = 10
CONVERGED_SPAN = 0.1
PROJECTION_TOLERANCE = 0.01
MAX_BISECTIONS = 30

if not hasattr(creator, "GryffinRosFitness"):
    creator.create("GryffinRosFitness", base.Fitness, weights=(-1.0,))
    creator.create("GryffinRosIndividual", list, fitness=creator.GryffinRosFitness)


@contextmanager
def seeded_python_random(rng: np.random.Generator) -> Iterator[None]:
    """DEAP draws from Python's global `random`: seed it from our generator and restore it afterwards."""
    saved = random.getstate()
    random.seed(int(rng.integers(2**63)))
    try:
        yield
    finally:
        random.setstate(saved)


def to_individuals(X: np.ndarray, fitness: np.ndarray | None = None) -> list:
    population = [creator.GryffinRosIndividual(map(float, x)) for x in X]
    if fitness is not None:
        for individual, value in zip(population, fitness):
            individual.fitness.values = (float(value),)
    return population


def crossover(space: SearchSpace, a: list, b: list) -> None:
    """In place, as DEAP's operators: uniform crossover for 2 genes, two-point for 3 or more."""
    if space.dim == 2:
        tools.cxUniform(a, b, indpb=0.5)
    elif space.dim >= 3:
        tools.cxTwoPoint(a, b)


def mutate(space: SearchSpace, X: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Per gene with p 0.2: continuous + N(0, 0.1 range), discrete + round(N(0, 0.1 range)), categorical resampled."""
    X = X.copy()
    hit = rng.random(X.shape) < GENE_MUTATION_PROB
    noise = rng.normal(0.0, MUTATION_SCALE, X.shape)
    for d, p in enumerate(space.parameters):
        rows = hit[:, d]
        if p.kind == "continuous":
            X[rows, d] += noise[rows, d]
        elif p.kind == "discrete":
            X[rows, d] += np.rint(noise[rows, d] * (space.n_options[d] - 1))
        else:
            X[rows, d] = rng.integers(0, space.n_options[d], int(rows.sum()))
    return space.clip(X)


def project_to_feasible(constraints: KnownConstraints, children: np.ndarray, parents: np.ndarray) -> np.ndarray:
    """Project children (B, D) onto the feasible set using their feasible parents (B, D); returns feasible points."""
    space = constraints.space
    out = children.copy()
    bad = np.flatnonzero(~constraints.feasible(out))
    if not bad.size:
        return out
    categorical = np.array([p.kind == "categorical" for p in space.parameters])
    own_categories = out[bad][:, categorical]
    # (i) the parent's categories
    out[np.ix_(bad, categorical)] = parents[np.ix_(bad, categorical)]
    still = bad[~constraints.feasible(out[bad])]
    if not still.size:
        return out
    # (ii) all constraints linear and the segment continuous: the exact boundary point, t* = the largest t in
    # [0, 1] with A (parent + t (child - parent)) <= b (a hair inside, then checked)
    planes = constraints.halfspaces()
    if planes is not None and planes[2] and not space.finite_idx.size:
        A, b, _ = planes
        start, step = parents[still], out[still] - parents[still]
        t = np.clip(line_limits(A, b, start, step)[1], 0.0, 1.0) * (1.0 - 1e-9)
        exact = space.clip(start + t[:, None] * step)
        ok = constraints.feasible(exact)
        out[still[ok]] = exact[ok]
        still = still[~ok]
        if not still.size:
            return out
    # (ii') otherwise bisection between the feasible parent and the infeasible child on continuous/discrete dims
    lo, hi = parents[still].copy(), out[still].copy()
    best = parents[still].copy()
    for _ in range(MAX_BISECTIONS):
        gap = np.abs(space.scaled(hi) - space.scaled(lo)).max(axis=1)
        open_ = gap >= PROJECTION_TOLERANCE
        if not open_.any():
            break
        mid = (lo + hi) / 2
        point = space.clip(mid)
        ok = constraints.feasible(point) & open_
        lo[ok], best[ok] = mid[ok], point[ok]
        shrink = ~ok & open_
        hi[shrink] = mid[shrink]
    out[still] = best
    # (iii) the child's own categories, where they keep the projected point feasible
    if categorical.any():
        retry = out[bad].copy()
        retry[:, categorical] = own_categories
        ok = constraints.feasible(retry)
        out[bad[ok]] = retry[ok]
    return out


class GeneticOptimizer:
    name = "genetic"

    def __init__(self, constraints: KnownConstraints, generations: int = MAX_GENERATIONS):
        self.constraints = constraints
        self.space = constraints.space
        self.generations = generations

    def optimize(self, acquisition: Acquisition, start: np.ndarray, rng: np.random.Generator
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Evolve a feasible population (M, D) -> (final population (M, D), alpha (M,)); every member is feasible."""
        space = self.space
        population = to_individuals(start, acquisition.evaluate(start))
        n_elite = max(1, int(round(ELITE_FRACTION * len(population))))
        with seeded_python_random(rng):
            for generation in range(self.generations):
                report("optimizing", generation / self.generations)
                elites = tools.selBest(population, n_elite)
                selected = tools.selTournament(population, len(population) - n_elite, TOURNAMENT_SIZE)
                parents = np.array(selected)
                if not len(parents):
                    break
                children = parents.copy()
                for i in range(0, len(children) - 1, 2):
                    if rng.random() < CROSSOVER_PROB:
                        a, b = list(children[i]), list(children[i + 1])
                        crossover(space, a, b)
                        children[i], children[i + 1] = a, b
                children = project_to_feasible(self.constraints, space.clip(children), parents)
                mutating = rng.random(len(children)) < MUTATION_PROB
                if mutating.any():
                    before = children[mutating]
                    children[mutating] = project_to_feasible(self.constraints, mutate(space, before, rng), before)
                # only children that differ from their parent need alpha again
                fitness = np.array([p.fitness.values[0] for p in selected])
                changed = np.flatnonzero((children != parents).any(axis=1))
                fitness[changed] = acquisition.evaluate(children[changed])
                elite_fitness = [e.fitness.values[0] for e in elites]
                population = to_individuals(children, fitness) + to_individuals(np.array(elites), elite_fitness)
                X = np.array(population)
                if (np.ptp(space.scaled(X), axis=0) < CONVERGED_SPAN).all():
                    break
        X = np.array(population)
        return X, np.array([ind.fitness.values[0] for ind in population])
