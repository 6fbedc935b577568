"""The paper's discrete benchmark surfaces (2 parameters x 21 ordered options, SI of the paper) with their known
constraints. Options are indices 0..20 (the paper's x_0..x_20); lower is better; each has a single constrained
optimum, found when it is evaluated."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

OPTIONS = 21


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


@dataclass(frozen=True)
class DiscreteSurface:
    name: str
    objective: Callable[[int, int], float]
    feasible: Callable[[int, int], bool]

    def cells(self) -> list[tuple[int, int]]:
        return [(i, j) for i in range(OPTIONS) for j in range(OPTIONS) if self.feasible(i, j)]

    def optimum(self) -> tuple[int, int]:
        return min(self.cells(), key=lambda cell: self.objective(*cell))


DISCRETE_SURFACES = {s.name: s for s in (
    DiscreteSurface("slope", slope, slope_feasible),
    DiscreteSurface("sphere", sphere, sphere_feasible),
    DiscreteSurface("michalewicz", michalewicz, michalewicz_feasible),
)}
