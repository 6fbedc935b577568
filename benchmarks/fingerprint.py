"""Proposals of fixed seeds, as JSON: the check that a refactoring changed no behaviour (issue #36 asks for it).

    .venv/bin/python -m benchmarks.fingerprint > after.json
    git worktree add /tmp/before <commit>
    (cd /tmp/before && PYTHONPATH=/tmp/before/gryffin_ros:/tmp/before <repo>/.venv/bin/python \
        <repo>/benchmarks/fingerprint.py) > before.json   # the package folder, or the root before the layout change
    cmp before.json after.json

Five asks of two proposals each with seed 0, every proposal told a deterministic synthetic result, on the flow
reactor, the redox candidates, the solvent blend (mixture equality) and a mixed continuous + categorical config with
the GP. Values are written as Python reprs: a refactoring must reproduce them to the last digit on the same machine
(the same computations in the same order); across machines or libraries they may differ in the last digits.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import gryffin_ros
from gryffin_ros.planner import Planner
from gryffin_ros.planner.config import load_config

ROOT = Path(gryffin_ros.__file__).resolve().parents[1]
MIXED_GP = {
    "name": "mixed_gp",
    "parameters": [{"name": "T", "type": "continuous", "low": 100.0, "high": 150.0},
                   {"name": "t", "type": "continuous", "low": 1.0, "high": 10.0},
                   {"name": "c", "type": "continuous", "low": 0.1, "high": 1.0},
                   {"name": "solvent", "type": "categorical", "options": ["THF", "DMF", "MeCN"],
                    "descriptors": {"THF": [66.0, 7.5], "DMF": [153.0, 36.7], "MeCN": [82.0, 37.5]}}],
    "objectives": [{"name": "yield", "goal": "max"}],
    "constraints": ["T < 140 if solvent == 'THF' else T < 149"],
    "general": {"surrogate": "gp"},
}
ASKS, BATCH = 5, 2


def synthetic(params: dict[str, Any], objectives: list[str]) -> dict[str, float]:
    """A deterministic result of any parameters (no hash(): string hashing differs between processes)."""
    value = sum((sum(map(ord, v)) % 97) / 97.0 if isinstance(v, str) else math.sin(1.7 * float(v))
                for v in params.values())
    return {name: value + 0.1 * k for k, name in enumerate(objectives)}


def fingerprint() -> dict[str, Any]:
    configs = {"flow_reactor": ROOT / "examples" / "flow_reactor.yaml",
               "redox": ROOT / "examples" / "redox_flow_battery.yaml",
               "solvent_blend": ROOT / "examples" / "solvent_blend.yaml", "mixed_gp": MIXED_GP}
    out: dict[str, Any] = {}
    for name, source in configs.items():
        planner = Planner(load_config(source), seed=0)
        objectives = [o.name for o in planner.config.objectives]
        rounds = []
        for _ in range(ASKS):
            proposals = planner.ask(BATCH)
            rounds.append([{k: repr(v) for k, v in p.params.items()} for p in proposals])
            for p in proposals:
                planner.tell({**p.params, **synthetic(p.params, objectives), "experiment_id": p.experiment_id})
        out[name] = rounds
    return out


if __name__ == "__main__":
    json.dump(fingerprint(), sys.stdout, indent=1, sort_keys=True)
    print()
