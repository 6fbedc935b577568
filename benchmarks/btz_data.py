"""The 57 benzothiadiazole (BTZ) molecules of `benchmarks/data/btz_ered_57.csv` (origin and license:
benchmarks/data/README.md), read without any library: used by `molecules.py` and by the peer harness's task module
`molecule_tasks.py`, which also runs in the peers' environments."""

from __future__ import annotations

import csv
from pathlib import Path

DATA = Path(__file__).resolve().parent / "data" / "btz_ered_57.csv"


def read_data(path: Path = DATA) -> tuple[dict[str, str], dict[str, float]]:
    """name -> SMILES, name -> ered (V vs Li/Li+), in the file's order."""
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    return {r["name"]: r["smiles"] for r in rows}, {r["name"]: float(r["ered"]) for r in rows}
