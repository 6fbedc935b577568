"""What a running campaign shows in the terminal: one self-updating line with experiments done and the best so far."""

from __future__ import annotations

import sys
import time

from ..planner import Observation
from ..planner.config import PlannerConfig
from ..planner.merit import best_of
from ..storage import CampaignStore


class Progress:
    """One self-updating terminal line: a bar, experiments done, the best experiment's objectives."""

    def __init__(self, budget: int):
        self.budget, self.start = budget, time.monotonic()
        self.interactive = sys.stdout.isatty()
        self._last = -1

    def show(self, done: int, best: dict[str, float] | None) -> None:
        if done == self._last:
            return
        self._last = done
        filled = int(30 * min(done, self.budget) / self.budget)
        best_text = "-" if best is None else "  ".join(f"{k} {v:.4g}" for k, v in best.items())
        line = (f"[{'#' * filled}{'.' * (30 - filled)}] {done:4d}/{self.budget} experiments  best: {best_text}  "
                f"({time.monotonic() - self.start:.1f} s)")
        print(("\r" + line) if self.interactive else line, end="" if self.interactive else "\n", flush=True)

    def close(self) -> None:
        if self.interactive:
            print(flush=True)


class BestSoFar:
    """Experiments so far and the objectives of the best one (`planner.merit.best_of`), read from a store that
    another process may be writing; each call reads only the observations stored since the last one."""

    def __init__(self, config: PlannerConfig):
        self.config = config
        self.observations: list[Observation] = []

    def __call__(self, store: CampaignStore) -> tuple[int, dict[str, float] | None]:
        self.observations += store.observations(skip=len(self.observations))
        best = best_of(self.config, self.observations)
        return len(self.observations), None if best is None else best.objectives
