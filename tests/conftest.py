"""Shared fixtures: small search spaces and the paper's constrained Branin."""

import math
import os
from pathlib import Path

import pytest

# `make test` and `make check` run two pytest-xdist workers on the two cores. Each gets a ROS domain of its own (the
# caller's and one 50 further), so the nodes of a test on one worker never see those of a test on the other, and one
# thread for torch's and BLAS's own parallelism (two workers with two threads each ran the unit tests 1.5 times
# slower than one process: 330 s of CPU against 213 s), set before anything imports them; processes a worker starts
# inherit both.
WORKER = os.environ.get("PYTEST_XDIST_WORKER", "")
if WORKER.startswith("gw") and WORKER[2:].isdigit():
    _base = int(os.environ.get("ROS_DOMAIN_ID") or os.getppid() % 101 + 1)
    os.environ["ROS_DOMAIN_ID"] = str((_base - 1 + 50 * int(WORKER[2:])) % 101 + 1)
    os.environ["OMP_NUM_THREADS"] = os.environ["MKL_NUM_THREADS"] = "1"

TESTS = Path(__file__).resolve().parent
# every test of these folders starts nodes or talks DDS
ROS_FOLDERS = (TESTS / "nodes", TESTS / "hosts")


def pytest_collection_modifyitems(config, items):
    """Mark the DDS tests `ros`: by folder, or one by one elsewhere (`make check` leaves them out)."""
    for item in items:
        if any(folder in Path(str(item.fspath)).parents for folder in ROS_FOLDERS):
            item.add_marker(pytest.mark.ros)


def branin(x0: float, x1: float) -> float:
    """Branin on the unit square (x1 in [-5, 10], x2 in [0, 15])."""
    x, y = 15 * x0 - 5, 15 * x1
    b, c, t = 5.1 / (4 * math.pi ** 2), 5 / math.pi, 1 / (8 * math.pi)
    return (y - b * x ** 2 + c * x - 6) ** 2 + 10 * (1 - t) * math.cos(x) + 10


def branin_feasible(params: dict) -> bool:
    """The paper's constraint (SI): two discs that remove two of Branin's three global minima."""
    x0, x1 = params["x0"], params["x1"]
    y0 = (x0 - 0.12389382) ** 2 + (x1 - 0.81833333) ** 2
    y1 = (x0 - 0.961652) ** 2 + (x1 - 0.165) ** 2
    return not (y0 < 0.2 ** 2 or y1 < 0.35 ** 2)


@pytest.fixture
def unit_square_config():
    return {
        "parameters": [{"name": "x0", "type": "continuous", "low": 0.0, "high": 1.0},
                       {"name": "x1", "type": "continuous", "low": 0.0, "high": 1.0}],
        "objectives": [{"name": "y", "goal": "min"}],
    }


@pytest.fixture
def mixed_config():
    return {
        "parameters": [
            {"name": "T", "type": "continuous", "low": 100.0, "high": 150.0},
            {"name": "n", "type": "discrete", "options": [1, 2, 5, 10]},
            {"name": "steps", "type": "discrete", "low": 0, "high": 4},
            {"name": "solvent", "type": "categorical", "options": ["THF", "DMF", "MeCN"],
             "descriptors": {"THF": [66.0, 7.5], "DMF": [153.0, 36.7], "MeCN": [82.0, 37.5]}},
        ],
        "objectives": [{"name": "yield", "goal": "max"}],
        "constraints": ["T < 140 if solvent == 'THF' else T < 149", "n * T <= 1000"],
    }
