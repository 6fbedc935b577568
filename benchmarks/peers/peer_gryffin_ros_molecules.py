"""Peer harness adapter: gryffin_ros with its default settings and molecules as SMILES options (RDKit's default
descriptors) where the task has them (benchmarks/molecule_tasks.py; see gryffin_ros_peer.py)."""

from gryffin_ros_peer import adapter

PEER, VERSION, DEFAULT_SEEDS, Optimizer = adapter(None, molecules=True)
