"""The molecular problem of `benchmarks/molecules.py` as a task of the peer harness (../shared/peers, `--task-module
molecule_tasks`): one categorical parameter whose options are the 57 benzothiadiazole (BTZ) molecules of
`benchmarks/data/btz_ered_57.csv` (origin and license: `benchmarks/data/README.md`), objective their DFT reduction
potential `ered` (V vs Li/Li+), minimized, without noise; 40 experiments, the first 5 the harness's common random
design. `smiles` (aligned with the options) is what a peer that reads molecules encodes (our planner's SMILES options,
BayBE's SubstanceParameter); the names peers give the options are `MoleculeParam.labels(seed)`. Peers that only know
numbers see the option index."""

from __future__ import annotations

import random

from problems import CatParam, Task

from benchmarks.btz_data import read_data  # the harness runs with the repository root on its PEER_PATH


class MoleculeParam(CatParam):
    """A categorical parameter whose options are molecules: `smiles[i]` is option i's structure.

    The names a peer gives the options come from `labels(seed)`: uninformative and in a new random order each seed.
    A model that knows nothing of the options breaks its ties by their order (BayBE's one-hot campaign proposes them
    in the order of their names until its data say otherwise), and the data's own names (entry numbers) put the best
    molecule fourth in alphabetical order: that would be measured as skill."""

    def __init__(self, name: str, smiles: dict[str, str]):
        super().__init__(name, list(smiles))
        self.smiles = list(smiles.values())

    def labels(self, seed: int) -> list[str]:
        """Option i's name in the run of `seed`."""
        order = random.Random(7919 * seed + 1).sample(range(len(self.options)), len(self.options))
        return [f"M{k:03d}" for k in order]


class Btz57(Task):
    name = "btz57"
    n_init = 5
    budget = 40

    def __init__(self):
        smiles, self.ered = read_data()
        self.params = [MoleculeParam("molecule", smiles)]
        self.names = list(smiles)
        self.optimum = min(self.ered.values())

    def feasible(self, x):
        return float(x[0]).is_integer() and 0 <= int(x[0]) < len(self.names)

    def objective(self, x):
        return self.ered[self.names[int(x[0])]]

    def is_optimum(self, x):
        return self.objective(x) == self.optimum

    def all_feasible(self):
        """Every point (peer_random draws from them without replacement)."""
        return [[i] for i in range(len(self.names))]


TASKS = {"btz57": Btz57}
