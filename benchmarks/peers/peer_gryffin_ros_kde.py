"""Peer harness adapter: gryffin_ros with general.surrogate = kde (see gryffin_ros_peer.py)."""

from gryffin_ros_peer import adapter

PEER, VERSION, DEFAULT_SEEDS, Optimizer = adapter("kde")
