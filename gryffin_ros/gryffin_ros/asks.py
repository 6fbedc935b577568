"""The ask queue of a campaign: every proposal is made on one thread, in the order asked, and can be stopped.

An ask waiting its turn reports "waiting" to its caller and is dropped if it is stopped before it starts; a running
one stops at its next checkpoint (`planner.reporting`) when its caller cancels it or the queue is closed (the
campaign stops serving: deactivation, shutdown). One thread, not the caller's: asks made on changing threads left
each thread's malloc arena holding its own large freed blocks (a planner node grew ~0.35 MB per experiment).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent import futures
from typing import TypeVar

from .planner.errors import GryffinRosError
from .planner.reporting import Cancelled, ProgressCallback

T = TypeVar("T")

# an ask queued behind another one says "waiting" this often
WAIT_REPORT_S = 0.25

CANCELED_BY_CLIENT = "canceled by the client; nothing was proposed"


class Stopped(Cancelled):
    """The queue was closed (the campaign stopped serving) while the ask waited or ran; nothing was proposed."""


class NotServing(GryffinRosError):
    """An ask came while the queue was closed."""


class AskQueue:
    def __init__(self, thread_name: str = "gryffin_planner_ask") -> None:
        self._thread = futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix=thread_name)
        self._lock = threading.Condition()
        self._running: set[threading.Event] = set()  # each ask in the queue or running: its stop request
        self._open = False
        self._why_closed = "the planner is not active; nothing was proposed"

    def open(self) -> None:
        with self._lock:
            self._open = True

    def close(self, reason: str, wait: bool = True) -> None:
        """Refuse new asks (raising NotServing(reason)); stop the queued and running ones (Stopped(reason)) and,
        with `wait`, return once they have ended."""
        with self._lock:
            self._open, self._why_closed = False, reason
            for stop in self._running:
                stop.set()
            if wait:
                self._lock.wait_for(lambda: not self._running)

    def settled(self) -> bool:
        """No ask is queued or running."""
        return not self.in_progress()

    def in_progress(self) -> int:
        """How many asks are queued or running."""
        with self._lock:
            return len(self._running)

    def shutdown(self) -> None:
        self.close("the planner is shutting down")
        self._thread.shutdown(wait=True)

    def run(self, make: Callable[[ProgressCallback], T], progress: ProgressCallback | None = None,
            cancelled: Callable[[], bool] = lambda: False) -> T:
        """`make(checkpoint)` on the queue's thread; `checkpoint(stage, fraction, ready)` passes the progress on to
        `progress` and raises Cancelled once `cancelled()` says so, Stopped once the queue is closed."""
        stop = threading.Event()
        with self._lock:
            if not self._open:
                raise NotServing(self._why_closed)
            self._running.add(stop)

        def checkpoint(stage: str, fraction: float, ready: int) -> None:
            if stop.is_set():
                raise Stopped(self._why_closed)
            if cancelled():
                raise Cancelled(CANCELED_BY_CLIENT)
            if progress is not None:
                progress(stage, fraction, ready)

        try:
            future = self._thread.submit(make, checkpoint)
            while True:
                try:
                    return future.result(timeout=WAIT_REPORT_S)
                except futures.TimeoutError:
                    if future.running():
                        continue
                    if stop.is_set() and future.cancel():
                        raise Stopped(self._why_closed) from None
                    if cancelled() and future.cancel():
                        raise Cancelled(CANCELED_BY_CLIENT) from None
                    if progress is not None:
                        progress("waiting", 0.0, 0)
        finally:
            with self._lock:
                self._running.discard(stop)
                self._lock.notify_all()
