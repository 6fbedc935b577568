"""The benchmarks folder is not a package (its scripts run as `python benchmarks/NAME.py`, importing each other as
siblings): its modules are tested the same way."""

import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCHMARKS) not in sys.path:
    sys.path.insert(0, str(BENCHMARKS))
