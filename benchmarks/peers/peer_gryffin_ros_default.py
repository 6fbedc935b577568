"""Peer harness adapter: gryffin_ros with its default settings (no general.surrogate; see gryffin_ros_peer.py)."""

from gryffin_ros_peer import adapter

PEER, VERSION, DEFAULT_SEEDS, Optimizer = adapter(None)
