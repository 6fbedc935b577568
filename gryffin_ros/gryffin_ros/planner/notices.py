"""One-time notices about configuration keys that are accepted for compatibility with Gryffin 1.0 but change nothing
here (its BNN, database, parallelism and verbosity settings). Each key is logged once per process, through the
standard `logging` module (logger ``gryffin_ros.config``), never printed."""

from __future__ import annotations

import logging
import threading

LOGGER = logging.getLogger("gryffin_ros.config")
_noted: set[str] = set()
_lock = threading.Lock()


def note_no_effect(key: str, why: str, level: int = logging.INFO) -> bool:
    """Log "'<key>' has no effect here: <why>" the first time `key` is met in this process; True if it was logged."""
    with _lock:
        if key in _noted:
            return False
        _noted.add(key)
    LOGGER.log(level, "'%s' has no effect here: %s", key, why)
    return True


def forget_notices() -> None:
    """Log every key again when next met (for tests)."""
    with _lock:
        _noted.clear()
