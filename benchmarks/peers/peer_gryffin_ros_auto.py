"""Peer harness adapter: gryffin_ros with general.surrogate = auto (see gryffin_ros_peer.py)."""

from gryffin_ros_peer import adapter

PEER, VERSION, DEFAULT_SEEDS, Optimizer = adapter("auto")
