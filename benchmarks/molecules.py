"""Molecules as options (#35): experiments until the molecule of lowest reduction potential is measured, with RDKit's
default descriptors against none (the options alone), over seeds.

Data: `benchmarks/data/btz_ered_57.csv`, every 25th (entry number divisible by 25) of the 1407 benzothiadiazole
(BTZ) derivatives of the redox-flow-battery case study: name, SMILES and the DFT reduction potential `ered` (V vs
Li/Li+), from `application_batteries/data/raw_data.csv` of github.com/aspuru-guzik-group/gryffin-known-constraints
(commit dfceff9949246c969b64fd0e8ca8679b48069167, MIT license, Copyright (c) 2022 Aspuru-Guzik group repo); paper:
Hickman, Aldeghi, Häse, Aspuru-Guzik, Digital Discovery 2022 (arXiv:2203.17241). One categorical parameter whose 57
options are the SMILES, objective `ered` minimized, without noise; a run ends when the best molecule is measured
(random choice needs (57 + 1) / 2 = 29 experiments on average).

    python -m benchmarks.molecules [--seeds 10] [--out benchmarks/results/molecules.md]
"""

from __future__ import annotations

import argparse
import logging
import statistics
import time
from pathlib import Path

from benchmarks.btz_data import read_data
from gryffin_ros.planner import Planner
from gryffin_ros.planner.config import load_config
from gryffin_ros.planner.molecules import MoleculeCache

VARIANTS = {"RDKit default descriptors": "default", "no descriptors": "none"}


def experiments_to_best(smiles: dict[str, str], ered: dict[str, float], descriptors: str, seed: int,
                        cache: MoleculeCache) -> int:
    """Experiments until the molecule of lowest `ered` is measured (each molecule is proposed at most once)."""
    config = load_config({"name": "btz", "parameters": [{"name": "molecule", "type": "categorical",
                                                         "options": smiles, "molecular_descriptors": descriptors}],
                          "objectives": [{"name": "ered", "goal": "min"}]}, molecule_cache=cache)
    planner = Planner(config, seed=seed)
    best = min(ered, key=ered.get)
    for count in range(1, len(smiles) + 1):
        (proposal,) = planner.ask()
        name = proposal.params["molecule"]
        planner.tell({"molecule": name, "ered": ered[name], "experiment_id": proposal.experiment_id})
        if name == best:
            return count
    raise AssertionError("every molecule was measured without the best one")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--variants", nargs="+", choices=sorted(VARIANTS.values()), default=list(VARIANTS.values()))
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "results" / "molecules.md")
    args = parser.parse_args()
    logging.basicConfig(level=logging.WARNING)
    logging.getLogger("gryffin_ros.planner.parameters").setLevel(logging.ERROR)  # the isomers, once per run
    smiles, ered = read_data()
    cache = MoleculeCache()
    lines = [f"# Molecules: experiments until the lowest-Ered BTZ of {len(smiles)} is measured "
             f"({args.seeds} seeds; random: {(len(smiles) + 1) / 2:g} on average)", "",
             "| descriptors | mean ± s.e. | median | per seed (0..) | s per run |", "|---|---|---|---|---|"]
    for label, descriptors in VARIANTS.items():
        if descriptors not in args.variants:
            continue
        start = time.perf_counter()
        counts = []
        for seed in range(args.seeds):
            counts.append(experiments_to_best(smiles, ered, descriptors, seed, cache))
            print(f"{descriptors} seed {seed}: {counts[-1]}", flush=True)
        seconds = (time.perf_counter() - start) / args.seeds
        error = statistics.stdev(counts) / len(counts) ** 0.5 if len(counts) > 1 else float("nan")
        lines.append(f"| {label} | {statistics.mean(counts):.1f} ± {error:.1f} | {statistics.median(counts):g} | "
                     f"{' '.join(map(str, counts))} | {seconds:.1f} |")
        print(lines[-1], flush=True)
    args.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
