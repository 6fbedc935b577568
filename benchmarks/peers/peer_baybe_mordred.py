"""Peer harness adapter: BayBE on molecular tasks, encoding MORDRED (see baybe_molecules.py)."""

from baybe_molecules import adapter

PEER, VERSION, DEFAULT_SEEDS, Optimizer = adapter("MORDRED")
