"""The molecular benchmark's data (a published subset, as documented) and its measure."""

import csv

import pytest

from benchmarks.btz_data import DATA, read_data
from benchmarks.molecules import experiments_to_best
from gryffin_ros.planner.molecules import MoleculeCache


def test_the_data_are_every_25th_btz_of_the_published_set():
    smiles, ered = read_data()
    assert len(smiles) == len(ered) == 57 and all(int(name.split("_")[1]) % 25 == 0 for name in smiles)
    with open(DATA, newline="") as handle:
        assert next(csv.reader(handle)) == ["name", "smiles", "ered"]
    assert 1.6 < min(ered.values()) < max(ered.values()) < 3.1  # V vs Li/Li+


@pytest.mark.parametrize("descriptors", ["default", "none"])
def test_a_run_ends_when_the_best_molecule_is_measured(descriptors):
    pytest.importorskip("rdkit")
    smiles, ered = read_data()
    few = dict(list(smiles.items())[:6])
    count = experiments_to_best(few, {n: ered[n] for n in few}, descriptors, 0, MoleculeCache())
    assert 1 <= count <= 6
