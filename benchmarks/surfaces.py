"""The paper's eight benchmark surfaces with their known constraints (SPEC section 4, SI of the paper).

Continuous surfaces live on the unit square [0, 1]^2 (parameters ``x0``, ``x1``) and are scaled inside, as in
Olympus: Branin, Schwefel, Dejong (sum |x|^0.5 on 10u - 5) and DiscreteAckley (a step function), the latter with two
constraint sets: the bands printed in the SI (``discreteackley``), which every one of the 50 100 published evaluations
satisfies (while 3 208 of them have x0 + x1 < 0.3), and x0 + x1 < 0.3 infeasible (``discreteackley_sum``), which
SPEC section 4 attributes to the published runs. Discrete surfaces have 2 parameters x 21 ordered options (indices
0..20, the paper's x_0..x_20): Slope, Sphere, Michalewicz and Camel. Lower is better everywhere; each discrete
surface has a single constrained optimum, found when it is evaluated.

Every surface gives its constraint as a vectorized callable (:func:`gryffin_ros.planner.vectorized`) and a planner
config, so the benchmark runner treats all of them alike.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from gryffin_ros.planner import vectorized

OPTIONS = 21
NAMES = ("x0", "x1")


# ---- continuous surfaces (vectorized over arrays of x0, x1 in [0, 1]) ------------------------------------------
def branin(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    u, v = 15.0 * np.asarray(x0) - 5.0, 15.0 * np.asarray(x1)
    b, c, t = 5.1 / (4 * math.pi ** 2), 5 / math.pi, 1 / (8 * math.pi)
    return (v - b * u ** 2 + c * u - 6.0) ** 2 + 10.0 * (1 - t) * np.cos(u) + 10.0


def branin_feasible(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """Two discs remove two of Branin's three global minima."""
    near_first = (x0 - 0.12389382) ** 2 + (x1 - 0.81833333) ** 2 < 0.2 ** 2
    near_third = (x0 - 0.961652) ** 2 + (x1 - 0.165) ** 2 < 0.35 ** 2
    return ~(near_first | near_third)


def schwefel(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """-sum x sin(sqrt|x|) on [-500, 500]^2 (Olympus's form, without the 418.98 d offset): optimum -837.97."""
    total = 0.0
    for x in (x0, x1):
        v = 1000.0 * np.asarray(x) - 500.0
        total = total - v * np.sin(np.sqrt(np.abs(v)))
    return total


def _schwefel_circles() -> tuple[np.ndarray, np.ndarray]:
    """20 infeasible discs: centres then radii drawn with numpy's legacy generator seeded 42 (paper's SI)."""
    legacy = np.random.RandomState(42)
    centres = np.array([legacy.uniform(0.0, 1.0, size=2) for _ in range(20)])
    radii = np.array([legacy.uniform(0.05, 0.15, size=1)[0] for _ in range(20)])
    return centres, radii


SCHWEFEL_CENTRES, SCHWEFEL_RADII = _schwefel_circles()


def schwefel_feasible(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    x0, x1 = np.asarray(x0, dtype=float), np.asarray(x1, dtype=float)
    distance = np.hypot(x0[..., None] - SCHWEFEL_CENTRES[:, 0], x1[..., None] - SCHWEFEL_CENTRES[:, 1])
    return ~(distance < SCHWEFEL_RADII).any(axis=-1)


def dejong(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """sum |x|^0.5 on [-5, 5]^2 (Olympus's Dejong)."""
    return np.sqrt(np.abs(10.0 * np.asarray(x0) - 5.0)) + np.sqrt(np.abs(10.0 * np.asarray(x1) - 5.0))


def dejong_feasible(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """A band along the diagonal and an annulus around the centre are infeasible: the minimum is unreachable."""
    y = (x0 - 0.5) ** 2 + (x1 - 0.5) ** 2
    return ~((np.abs(x0 - x1) < 0.1) | ((0.05 < y) & (y < 0.15)))


_ACKLEY_GRID = np.linspace(-50.0, 50.0, 10)


def discrete_ackley(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """Olympus's DiscreteAckley: a rugged step function with values 0..4 and its minimum 0 where |100x - 50| < 1."""
    p = np.stack([100.0 * np.asarray(x0, dtype=float) - 50.0, 100.0 * np.asarray(x1, dtype=float) - 50.0], axis=-1)
    largest = np.abs(p).max(axis=-1)
    level = 5 - sum((largest < b ** 2).astype(int) for b in (1.0, 2.0, 3.0, 4.0, 5.0))
    off_grid = np.abs(p[..., None] - _ACKLEY_GRID).min(axis=-1).max(axis=-1)
    grid_level = 5 - sum((off_grid < b ** 2).astype(int) for b in (1.25, 2.0, 2.5))
    return np.minimum(4, np.minimum(level, grid_level)).astype(float)


def discrete_ackley_feasible(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """The constraint printed in the SI (and obeyed by the published runs): two bands per coordinate are infeasible."""
    bad0 = ((0.41 < x0) & (x0 < 0.46)) | ((0.54 < x0) & (x0 < 0.59))
    bad1 = ((0.34 < x1) & (x1 < 0.41)) | ((0.59 < x1) & (x1 < 0.66))
    return ~(bad0 | bad1)


def discrete_ackley_sum_feasible(x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """The variant SPEC section 4 names: x0 + x1 < 0.3 is infeasible."""
    return ~(np.asarray(x0) + np.asarray(x1) < 0.3)


# ---- discrete surfaces (option indices 0..20) ----------------------------------------------------------------
def slope(i: int, j: int) -> float:
    return float(i + j)


def slope_feasible(i: int, j: int) -> bool:
    y = i * i + j * j
    return not (5 < y < 25 or 70 < y < 110 or 200 < y < 300)


def sphere(i: int, j: int) -> float:
    return float((i - 10) ** 2 + (j - 10) ** 2)


def sphere_feasible(i: int, j: int) -> bool:
    return i not in (9, 11) and j not in (9, 11)


def michalewicz(i: int, j: int) -> float:
    """-sum_k sin(v_k) sin(k v_k^2 / pi)^20 with v = index * pi / 20."""
    return -sum(math.sin(v) * math.sin(k * v * v / math.pi) ** 20
                for k, v in enumerate((i * math.pi / 20, j * math.pi / 20), start=1))


def michalewicz_feasible(i: int, j: int) -> bool:
    y = (i - 14) ** 2 + (j - 10) ** 2
    if 5 < y < 30:
        return False
    if 12.5 < i < 15.5 and j < 5.5:
        return False
    return not (8.5 < j < 11.5 and i < 9.5)


def _camel_raw(v0: float, v1: float) -> float:
    """Olympus's Camel: a product of four quadratic wells (two deep, two shallow) plus two Gaussian bumps."""
    v = np.array([v0, v1])

    def well(centre: tuple[float, float], weights: tuple[float, float], offset: float, coupled: bool) -> float:
        d = v - np.array(centre)
        return float(np.sum(np.array(weights) * d ** 2) + offset + (np.prod(d) if coupled else 0.0))

    def bump(centre: tuple[float, float]) -> float:
        return 3000.0 * math.exp(-float(np.sum((v - np.array(centre)) ** 2)) / 0.25)

    wells = (well((-1.0, 0.0), (4.0, 1.0), 0.01, True) * well((1.0, 0.0), (4.0, 1.0), 0.01, True)
             * well((-1.0, 1.5), (1.0, 1.0), 0.075, False) * well((1.0, -1.5), (1.0, 1.0), 0.075, False))
    return wells + bump((-0.5, -1.0)) + bump((0.5, 1.0))


def camel(i: int, j: int) -> float:
    """log(Camel) with v = 6 i / 20 - 3, as in the paper's scripts (Olympus divides by 21, which moves the optimum)."""
    return math.log(_camel_raw(6 * i / 20 - 3, 6 * j / 20 - 3))


def _camel_infeasible() -> frozenset[tuple[int, int]]:
    """100 random pairs (numpy's legacy generator seeded 42: all first indices, then all second ones) plus the other
    minima (7, 11), (7, 15) and (13, 5): 94 distinct cells."""
    legacy = np.random.RandomState(42)
    first = legacy.choice(range(OPTIONS), size=100, replace=True)
    second = legacy.choice(range(OPTIONS), size=100, replace=True)
    return frozenset({(int(a), int(b)) for a, b in zip(first, second)} | {(7, 11), (7, 15), (13, 5)})


CAMEL_INFEASIBLE = _camel_infeasible()


def camel_feasible(i: int, j: int) -> bool:
    return (i, j) not in CAMEL_INFEASIBLE


# ---- the common interface ------------------------------------------------------------------------------------
def option_index(value: Any) -> int:
    """A discrete option in either form: the ordinal 0..20 or the categorical 'x_12'."""
    return int(str(value).removeprefix("x_")) if isinstance(value, str) else int(round(float(value)))


@dataclass(frozen=True)
class DiscreteSurface:
    name: str
    objective: Callable[[int, int], float]
    feasible: Callable[[int, int], bool]
    kind: str = field(default="discrete", init=False)

    def cells(self) -> list[tuple[int, int]]:
        return [(i, j) for i in range(OPTIONS) for j in range(OPTIONS) if self.feasible(i, j)]

    def optimum(self) -> tuple[int, int]:
        return min(self.cells(), key=lambda cell: self.objective(*cell))

    @cached_property
    def optimum_value(self) -> float:
        return self.objective(*self.optimum())

    def config(self, variant: str = "ordinal") -> dict:
        """'ordinal': discrete 0..20 (a 1-d ordinal descriptor); 'categorical': options x_0..x_20, no descriptors."""
        if variant == "ordinal":
            parameters = [{"name": n, "type": "discrete", "low": 0, "high": OPTIONS - 1} for n in NAMES]
        elif variant == "categorical":
            parameters = [{"name": n, "type": "categorical", "options": [f"x_{i}" for i in range(OPTIONS)]}
                          for n in NAMES]
        else:
            raise ValueError(f"unknown variant {variant!r}; use 'ordinal' or 'categorical'")
        return {"parameters": parameters, "objectives": [{"name": "y", "goal": "min"}]}

    def cell(self, params: Mapping[str, Any]) -> tuple[int, int]:
        return option_index(params["x0"]), option_index(params["x1"])

    def evaluate(self, params: Mapping[str, Any]) -> float:
        return self.objective(*self.cell(params))

    def is_feasible(self, params: Mapping[str, Any]) -> bool:
        return self.feasible(*self.cell(params))

    def is_optimum(self, params: Mapping[str, Any]) -> bool:
        return self.cell(params) == self.optimum()

    @cached_property
    def constraint(self) -> Callable:
        table = np.array([[self.feasible(i, j) for j in range(OPTIONS)] for i in range(OPTIONS)])

        @vectorized
        def known_constraint(columns: Mapping[str, np.ndarray]) -> np.ndarray:
            i = np.array([option_index(v) for v in columns["x0"]], dtype=int)
            j = np.array([option_index(v) for v in columns["x1"]], dtype=int)
            return table[i, j]

        known_constraint.__name__ = f"{self.name}_feasible"
        return known_constraint


@dataclass(frozen=True)
class ContinuousSurface:
    name: str
    objective: Callable[[np.ndarray, np.ndarray], np.ndarray]
    feasible: Callable[[np.ndarray, np.ndarray], np.ndarray]
    kind: str = field(default="continuous", init=False)

    def config(self, variant: str = "continuous") -> dict:
        parameters = [{"name": n, "type": "continuous", "low": 0.0, "high": 1.0} for n in NAMES]
        return {"parameters": parameters, "objectives": [{"name": "y", "goal": "min"}]}

    def evaluate(self, params: Mapping[str, Any]) -> float:
        return float(self.objective(np.array([float(params["x0"])]), np.array([float(params["x1"])]))[0])

    def is_feasible(self, params: Mapping[str, Any]) -> bool:
        return bool(self.feasible(np.array([float(params["x0"])]), np.array([float(params["x1"])]))[0])

    def feasible_fraction(self, points: int = 1001) -> float:
        """Fraction of a regular grid (points x points over the unit square) that is feasible."""
        x0, x1 = np.meshgrid(np.linspace(0, 1, points), np.linspace(0, 1, points), indexing="ij")
        return float(self.feasible(x0.ravel(), x1.ravel()).mean())

    @cached_property
    def constrained_optimum(self) -> tuple[tuple[float, float], float]:
        """((x0, x1), value): the best feasible point of a 1001^2 grid, refined by ever finer local grids."""
        centre, half, best = (0.5, 0.5), 0.5, (None, math.inf)
        for points in (1001, 201, 201, 201, 201):
            axis0 = np.clip(np.linspace(centre[0] - half, centre[0] + half, points), 0.0, 1.0)
            axis1 = np.clip(np.linspace(centre[1] - half, centre[1] + half, points), 0.0, 1.0)
            x0, x1 = (a.ravel() for a in np.meshgrid(axis0, axis1, indexing="ij"))
            ok = self.feasible(x0, x1)
            values = np.where(ok, self.objective(x0, x1), np.inf)
            k = int(np.argmin(values))
            if values[k] <= best[1]:
                best = ((float(x0[k]), float(x1[k])), float(values[k]))
            centre, half = best[0], 4 * half / (points - 1)
        return best

    @property
    def optimum_value(self) -> float:
        return self.constrained_optimum[1]

    @cached_property
    def constraint(self) -> Callable:
        @vectorized
        def known_constraint(columns: Mapping[str, np.ndarray]) -> np.ndarray:
            x0, x1 = (np.asarray(columns[n], dtype=float) for n in NAMES)
            return np.asarray(self.feasible(x0, x1), dtype=bool)

        known_constraint.__name__ = f"{self.name}_feasible"
        return known_constraint


DISCRETE_SURFACES = {s.name: s for s in (
    DiscreteSurface("slope", slope, slope_feasible),
    DiscreteSurface("sphere", sphere, sphere_feasible),
    DiscreteSurface("michalewicz", michalewicz, michalewicz_feasible),
    DiscreteSurface("camel", camel, camel_feasible),
)}

CONTINUOUS_SURFACES = {s.name: s for s in (
    ContinuousSurface("branin", branin, branin_feasible),
    ContinuousSurface("schwefel", schwefel, schwefel_feasible),
    ContinuousSurface("dejong", dejong, dejong_feasible),
    ContinuousSurface("discreteackley", discrete_ackley, discrete_ackley_feasible),
    ContinuousSurface("discreteackley_sum", discrete_ackley, discrete_ackley_sum_feasible),
)}

SURFACES: dict[str, DiscreteSurface | ContinuousSurface] = {**CONTINUOUS_SURFACES, **DISCRETE_SURFACES}
