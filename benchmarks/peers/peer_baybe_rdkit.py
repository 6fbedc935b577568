"""Peer harness adapter: BayBE on molecular tasks, encoding RDKIT2DDESCRIPTORS (see baybe_molecules.py)."""

from baybe_molecules import adapter

PEER, VERSION, DEFAULT_SEEDS, Optimizer = adapter("RDKIT2DDESCRIPTORS")
