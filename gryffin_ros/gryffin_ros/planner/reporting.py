"""Progress of a running ask, reported to whoever asked, and cooperative cancellation: the caller's callback is
called at checkpoints of the optimization (each well under a second apart) and may raise `Cancelled` to stop it."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from .errors import GryffinRosError

# (stage, fraction of the ask done in [0, 1], proposals of the batch chosen so far)
ProgressCallback = Callable[[str, float, int], None]

_callback: ContextVar[ProgressCallback | None] = ContextVar("gryffin_ros_progress", default=None)


class Cancelled(GryffinRosError):
    """The caller stopped the ask; nothing was proposed and the planner is as before."""


@contextmanager
def reporting(callback: ProgressCallback | None) -> Iterator[None]:
    """Report the progress of the asks made inside this block (in this thread) to `callback`."""
    token = _callback.set(callback)
    try:
        yield
    finally:
        _callback.reset(token)


def report(stage: str, fraction: float, ready: int = 0) -> None:
    """A checkpoint: tell the caller where the ask is; raises whatever the caller's callback raises (Cancelled)."""
    callback = _callback.get()
    if callback is not None:
        callback(stage, min(max(float(fraction), 0.0), 1.0), ready)
