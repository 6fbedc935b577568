"""`Campaign`: the one owner of a campaign — its store, its planner and its bookkeeping — without ROS.

The planner node, `gryffin-ros campaign` (with or without ROS) and the benchmarks that run campaigns all go through
it; the node only translates messages. What it guarantees:

- the store is held exclusively (a second process on the same file is refused at once, naming the holder);
- each observation is validated exactly once, when it arrives, and committed before `observe` returns (a caller
  acknowledges after `observe`, so nothing acknowledged can be lost); never reported twice;
- the store is the campaign's record (proposals, claims, observations, rejections, the ask and proposal counts);
  the campaign keeps a cache of it (a planner `History`) and hands the planner a snapshot of it for each proposal:
  the planner keeps no copy, and a proposal that could not be stored leaves nothing to undo;
- restarting on the same store continues the campaign: same seed, same counts, the experiments still owed.

Serving a lab (what the planner node does with it, tested here without ROS): `serve` opens the ask queue
(`asks.AskQueue`: every proposal on one thread, in order, each stoppable by its caller) and returns the experiments
still owed, to be announced again; `recommend` is a lab's ask; `auto_proposals` are the next proposals published
unasked once nothing is owed — not after an ask failed, until new data arrives; `owed_after_quiet` are the experiments
to announce again when nothing has come in for REMIND_AFTER_S; `stop_serving` stops the running asks.

Pending proposals follow one rule: a proposal stays pending until an observation reports it. Proposals published
without being asked for (auto-propose) are *unclaimed*; `claim` (the node's recommend) hands out unclaimed pending
proposals first, each once, and asks the planner only for the rest, so an auto-published batch is never left
behind by a lab that asks for its experiments. An instrument that claims under its name is handed back what it
claimed and has not reported before anything else: asking again is safe when an answer was lost (a network cut),
and no other instrument is given those experiments, also after a restart (claims are stored).
"""

from __future__ import annotations

import copy
import ctypes
import logging
import threading
import time
import uuid
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from .asks import AskQueue, NotServing
from .planner import Observation, Planner, Proposal
from .planner.config import PlannerConfig, load_config, read_config
from .planner.errors import GryffinRosError, ObservationError
from .planner.history import History
from .planner.molecules import MoleculeCache
from .planner.reporting import Cancelled, ProgressCallback, reporting
from .storage import CampaignStore

logger = logging.getLogger(__name__)

# While another proposal holds the planner, a caller with a progress callback hears "waiting" this often.
WAIT_REPORT_S = 0.25
# experiments still owed after this long without an observation are announced again (a report may have been lost)
REMIND_AFTER_S = 5.0

ConstraintArg = Callable[[dict], bool] | Sequence[Callable[[dict], bool]] | None


class Rejected(GryffinRosError):
    """An observation the campaign refuses for its id (already reported, or never proposed); nothing is stored."""


def _malloc_trim() -> Callable[[int], int] | None:
    try:
        return ctypes.CDLL(None).malloc_trim  # the C library this process runs on
    except (OSError, AttributeError):  # not glibc (musl, macOS): the allocator's own policy stands
        return None


_MALLOC_TRIM = _malloc_trim()


def give_back_freed_memory() -> None:
    """Return heap memory freed by an ask to the system. An ask allocates and frees matrices of tens of MB; glibc
    keeps freed blocks for reuse, so a long campaign's resident memory rose with the largest ask so far (a campaign
    of 1250 experiments in one process: 487 MB, with this after each ask 345 MB; about 5 ms per call)."""
    if _MALLOC_TRIM is not None:
        _MALLOC_TRIM(0)


class CampaignClosed(GryffinRosError):
    """The campaign has been closed (the process is shutting down); nothing more is stored."""


class Campaign:
    """A campaign over a store (default: in memory). `settings` override `general` keys that choose how to optimize,
    not what (e.g. ``{"acquisition_optimizer": "genetic"}``): they are applied after the campaign's config hash, so
    the same store can be resumed with other settings."""

    def __init__(self, config: Mapping | str | Path, storage: str | Path = ":memory:", *, seed: int | None = None,
                 known_constraints: ConstraintArg = None, settings: Mapping[str, Any] | None = None,
                 accept_unsolicited: bool = False, base_dir: str | Path | None = None):
        raw = read_config(config)
        if base_dir is None and isinstance(config, (str, Path)):
            base_dir = Path(config).resolve().parent
        base = Path(base_dir) if base_dir is not None else None
        # RDKit's values for SMILES options are kept in the store: a restarted campaign does no RDKit work
        self._molecules = MoleculeCache(CampaignStore.molecule_values_at(storage))
        checked = load_config(raw, base, self._molecules)  # validates; its hash identifies the campaign in the store
        self.name = checked.name
        self.accept_unsolicited = accept_unsolicited
        self._raw, self._base = checked.raw, base
        self.store = CampaignStore(storage, checked.raw, checked.hash)
        try:
            self.store.add_molecule_values(self._molecules.computed)
            stored_seed = self.store.get_meta("seed")
            if seed is None and stored_seed is not None:  # a campaign keeps its seed
                seed = int(stored_seed)
            config_used = self._tuned(settings) if settings else checked
            # a new campaign: the seed given, else the config's, else a random one (the Planner's rule)
            self.planner = Planner(config_used, known_constraints, seed)
            self.store.set_meta("seed", str(self.planner.seed))
            # the cache of the store: what is stored, as the planner reads it
            self._history = History(self.store.observations(), {p.experiment_id: p for p in self.store.pending()},
                                    int(self.store.get_meta("ask_count") or 0),
                                    int(self.store.get_meta("proposal_count") or 0))
            self.planner.history = self._history.snapshot()
        except BaseException:
            self.store.close()
            raise
        self._state_lock = threading.Condition()  # the cache and bookkeeping; never held while the planner works
        self._active = 0  # observe() calls in progress (close waits for them)
        self._closed = False
        self._planner_lock = threading.Lock()  # the planner: one ask or one ranking at a time
        self._arriving: set[str] = set()  # ids of observations being committed (a concurrent duplicate is refused)
        self._unclaimed: list[str] = []  # pending ids published but not yet handed to anyone asking
        self._claims: dict[str, str] = self.store.claims()  # pending id -> the instrument it was handed to
        self._best = self.planner.best()
        self._best_stale = False  # an observation arrived while the planner was busy
        self._state = "idle"
        self.asks = AskQueue()  # closed until `serve`
        self._blocked = False  # an ask failed: nothing is proposed unasked until new data arrives
        self._last_input = time.monotonic()
        self.last_ask_s: float | None = None
        self.last_error: str | None = None

    def _tuned(self, settings: Mapping[str, Any]) -> PlannerConfig:
        tuned = copy.deepcopy(self._raw)
        tuned.setdefault("general", {}).update(settings)
        return load_config(tuned, self._base, self._molecules)

    def use_settings(self, settings: Mapping[str, Any]) -> None:
        """Change settings (as `settings` at construction: how to optimize, not what) from the next proposal on;
        waits for a running one. Raises ConfigError, changing nothing, for a value the config would refuse."""
        config = self._tuned(settings)
        with self._planner_lock:
            self.planner.config = config

    # ---- read-outs -----------------------------------------------------------------------------------------
    @property
    def config(self) -> PlannerConfig:
        return self.planner.config

    @property
    def seed(self) -> int:
        return self.planner.seed

    @property
    def n_observations(self) -> int:
        with self._state_lock:
            return len(self._history.observations)

    @property
    def pending(self) -> list[Proposal]:
        """Proposals still owed an observation, oldest first."""
        with self._state_lock:
            return list(self._history.pending.values())

    def history(self) -> History:
        """A snapshot of what the campaign has stored: observations, pending proposals, ask and proposal counts."""
        with self._state_lock:
            return self._history.snapshot()

    @property
    def best(self) -> Observation | None:
        with self._state_lock:
            return self._best

    @property
    def warnings(self) -> list[str]:
        """Known constraints that exclude nothing (found when the feasible region is first studied)."""
        return self.planner.constraint_warnings

    def status(self) -> dict[str, Any]:
        """Where the campaign stands (the node's status message)."""
        warnings = self.warnings  # the first time this studies the domain: not under the lock observations need
        with self._state_lock:
            best = self._best
            history = self._history
            return {
                "campaign": self.name, "n_observations": len(history.observations),
                "n_pending": len(history.pending), "n_failed": history.n_failed,
                "state": self._state,
                "best": None if best is None else {"experiment_id": best.experiment_id, "params": best.params,
                                                   "objectives": best.objectives},
                "warnings": warnings,
            }

    # ---- observations --------------------------------------------------------------------------------------
    def observe(self, item: Mapping[str, Any] | Observation, raw: str | None = None) -> Observation:
        """Validate one observation, commit it with the message it came in (`raw`), then teach the planner unless
        it is busy (then before its next proposal). Raises ObservationError or Rejected (nothing stored)."""
        with self._state_lock:
            if self._closed:
                raise CampaignClosed(f"campaign '{self.name}' is closed; the observation was not stored")
            self._active += 1
        try:
            return self._observe(item, raw)
        except (ObservationError, Rejected) as exc:
            self.reject(str(exc), raw, item.get("experiment_id") if isinstance(item, Mapping) else None)
            raise
        finally:
            with self._state_lock:
                self._active -= 1
                self._state_lock.notify_all()

    def _observe(self, item: Mapping[str, Any] | Observation, raw: str | None) -> Observation:
        observation = self.planner.parse_observation(item)
        with self._state_lock:
            experiment_id = observation.experiment_id
            if experiment_id is None:
                if not self.accept_unsolicited:
                    raise Rejected("an observation needs the experiment_id of the proposal it reports")
                experiment_id = observation.experiment_id = str(uuid.uuid4())
            if self._history.reported(experiment_id) or experiment_id in self._arriving:
                raise Rejected(f"experiment_id '{experiment_id}' was already reported; the first report stands")
            if experiment_id not in self._history.pending and not self.accept_unsolicited:
                raise Rejected(f"unknown experiment_id '{experiment_id}': this planner did not propose it (set "
                               "accept_unsolicited to accept prior data)")
            # reserved under the lock: a concurrent duplicate is refused above, and nobody is handed it meanwhile
            self._arriving.add(experiment_id)
            was_unclaimed = experiment_id in self._unclaimed
            if was_unclaimed:
                self._unclaimed.remove(experiment_id)
        try:
            self.store.add_observation(observation, raw)
        except BaseException:
            with self._state_lock:
                self._arriving.discard(experiment_id)
                if was_unclaimed:
                    self._unclaimed.insert(0, experiment_id)
            raise
        with self._state_lock:  # stored: now in the cache
            self._history.add_observations([observation])
            self._arriving.discard(experiment_id)
            self._claims.pop(experiment_id, None)
            self._last_input, self._blocked = time.monotonic(), False
            self._best_stale = True
        if self._planner_lock.acquire(blocking=False):  # never wait for a running optimization here
            try:
                self._rank()
            finally:
                self._planner_lock.release()
        return observation

    def reject(self, reason: str, raw: str | None = None, experiment_id: Any = None) -> None:
        """Record a refused observation in the store (the node calls this for messages it cannot even parse). A
        record that cannot be written is logged, never raised: the refusal itself has been said already."""
        with self._state_lock:
            if self._closed:
                return
            self._active += 1
        try:
            self.store.add_rejection(experiment_id if isinstance(experiment_id, str) else None, reason, raw)
        except Exception:  # noqa: BLE001
            logger.exception("could not record a refused observation in the store")
        finally:
            with self._state_lock:
                self._active -= 1
                self._state_lock.notify_all()

    def _rank(self) -> None:
        """The best observation of what is stored now (caller holds the planner lock); the planner's values grow
        with the history. If ranking fails (a bug), it is logged and tried again after the next proposal: the
        observation is stored whatever happens here."""
        with self._state_lock:
            if not self._best_stale:
                return
            self._best_stale = False
            self.planner.history = self._history.snapshot()
        try:
            best = self.planner.best()
        except Exception:  # noqa: BLE001
            logger.exception("could not rank the observations; the best is looked for again after the next proposal")
            with self._state_lock:
                self._best_stale = True
            return
        with self._state_lock:
            self._best = best

    # ---- proposals -----------------------------------------------------------------------------------------
    def propose(self, n: int | None = None, claimed: bool = True,
                progress: ProgressCallback | None = None) -> list[Proposal]:
        """`n` new proposals (default general.batches), stored before they are returned. `claimed=False` marks
        them as published without being asked for (auto-propose), so that `claim` hands them out later.
        `progress(stage, fraction, ready)` is called at checkpoints of the optimization (the status says
        "optimizing" then; stage "waiting" while another proposal holds the planner) and may stop the proposal by
        raising `Cancelled`: nothing is then stored or pending, and the planner is as before."""
        self._acquire_planner(progress)
        try:
            with reporting(progress):
                return self._propose(n, claimed)
        finally:
            self._planner_lock.release()

    def _acquire_planner(self, progress: ProgressCallback | None) -> None:
        if progress is None:
            self._planner_lock.acquire()
            return
        while not self._planner_lock.acquire(timeout=WAIT_REPORT_S):
            progress("waiting", 0.0, 0)  # may raise Cancelled: nothing was held

    def _propose(self, n: int | None, claimed: bool) -> list[Proposal]:
        with self._state_lock:
            if self._closed:
                raise CampaignClosed(f"campaign '{self.name}' is closed; nothing is proposed")
            self._state = "optimizing"
            self.planner.history = self._history.snapshot()  # what is stored now
        try:
            try:
                proposals, ask_count, proposal_count = self.planner.draw(n)
            finally:
                give_back_freed_memory()
            # stored before they count as proposed: one that could not be stored was never proposed
            self.store.add_proposals(proposals, {"ask_count": str(ask_count), "proposal_count": str(proposal_count)})
        except BaseException as exc:
            with self._state_lock:
                self._state = "idle" if isinstance(exc, Cancelled) else "error"
            raise
        with self._state_lock:
            self._history.add_proposals(proposals, ask_count, proposal_count)
            if not claimed:
                self._unclaimed += [p.experiment_id for p in proposals]
            self._state = "idle"
        self._rank()  # what arrived while optimizing
        return proposals

    def claim(self, n: int | None = None, progress: ProgressCallback | None = None,
              instrument: str = "") -> list[Proposal]:
        """`n` proposals for someone who asks (the node's recommend): unclaimed pending ones first, each handed out
        once, then new ones (`progress` as in `propose`). An `instrument` (a name unique in the lab) is first
        handed back the experiments it claimed before and has not reported, oldest first: asking again after a
        lost answer returns the same experiments, and they are never handed to anyone else."""
        n = self.config.general.batches if n is None else n
        with self._state_lock:
            pending = self._history.pending
            owned = [i for i, owner in self._claims.items() if instrument and owner == instrument
                     and i in pending][:n]
            room = n - len(owned)
            taken, self._unclaimed = self._unclaimed[:room], self._unclaimed[room:]
            handed = [pending[i] for i in owned + taken]
        made: list[Proposal] = []
        if len(handed) < n:
            try:
                made = self.propose(n - len(handed), progress=progress)
            except BaseException:
                with self._state_lock:  # nothing was handed out: the unclaimed stay unclaimed
                    self._unclaimed[:0] = [i for i in taken if i in self._history.pending]
                raise
        if instrument:
            fresh = taken + [p.experiment_id for p in made]
            if fresh:
                self.store.add_claims(fresh, instrument)  # stored before anyone is told
                with self._state_lock:
                    self._claims.update((i, instrument) for i in fresh if i in self._history.pending)
        return handed + made

    def mark_unclaimed(self) -> None:
        """Every pending proposal not claimed by a named instrument becomes unclaimed again (after a restart they
        are announced to everyone; an instrument's claims stay its own)."""
        with self._state_lock:
            self._unclaimed = [i for i in self._history.pending if i not in self._claims]

    # ---- serving a lab ---------------------------------------------------------------------------------------
    def serve(self) -> list[Proposal]:
        """Take asks from now on; proposals are published unasked again. Returns the experiments still owed, each
        now unclaimed unless a named instrument holds it: announce them (after a restart or a pause)."""
        with self._state_lock:
            self._blocked, self._last_input = False, time.monotonic()
        self.mark_unclaimed()
        self.asks.open()
        return self.pending

    def stop_serving(self, reason: str, wait: bool = True) -> None:
        """Refuse new asks and stop the running ones at their next checkpoint (their callers hear `reason`); with
        `wait`, return once they have ended. Observations are still taken until `close`."""
        self.asks.close(reason, wait)

    def recommend(self, n: int | None = None, *, instrument: str = "", claimed: bool = True,
                  progress: ProgressCallback | None = None, cancelled: Callable[[], bool] = lambda: False
                  ) -> list[Proposal]:
        """A lab's ask, through the queue: `claim(n, instrument)` (`claimed=False`: new proposals published unasked,
        as `propose(n, False)`). `progress` hears the stages (and "waiting" while queued); the ask stops at its next
        checkpoint once `cancelled()` (Cancelled) or `stop_serving` (asks.Stopped). A failure is raised as a
        GryffinRosError (a bug too, logged) and blocks unasked proposals until new data arrives."""
        started = time.monotonic()

        def make(checkpoint: ProgressCallback) -> list[Proposal]:
            if claimed:
                return self.claim(n, checkpoint, instrument)
            return self.propose(n, claimed=False, progress=checkpoint)

        try:
            proposals = self.asks.run(make, progress, cancelled)
        except (Cancelled, NotServing):
            raise
        except Exception as exc:
            if not isinstance(exc, GryffinRosError):  # a bug: report it, keep the campaign and its data alive
                logger.exception("internal error while proposing")
                exc = GryffinRosError(f"internal error: {exc!r}")
            with self._state_lock:
                self._blocked, self.last_error = True, str(exc)
            raise exc from None
        with self._state_lock:
            self.last_ask_s = time.monotonic() - started
        return proposals

    def auto_proposals(self, n: int | None = None, progress: ProgressCallback | None = None) -> list[Proposal]:
        """The next proposals to publish unasked: none while experiments are owed, while not serving, or after a
        failed ask until new data arrives. Raises as `recommend`."""
        with self._state_lock:
            if self._blocked or self._history.pending or self._closed:
                return []
        try:
            return self.recommend(n, claimed=False, progress=progress)
        except NotServing:
            return []

    def owed_after_quiet(self) -> list[Proposal]:
        """The experiments still owed once nothing has come in for REMIND_AFTER_S (then the quiet spell starts
        over): announce them again, a report or an announcement may have been lost."""
        with self._state_lock:
            if time.monotonic() - self._last_input <= REMIND_AFTER_S:
                return []
            self._last_input = time.monotonic()
            return list(self._history.pending.values())

    def recent_rejections(self, window_s: float) -> list[str]:
        """Reasons of the observations refused in the last `window_s` seconds, oldest first (from the store)."""
        with self._state_lock:
            if self._closed:
                return []
            self._active += 1
        try:
            return [r["reason"] for r in self.store.rejections(since=time.time() - window_s)]
        finally:
            with self._state_lock:
                self._active -= 1
                self._state_lock.notify_all()

    # ---- lifetime ------------------------------------------------------------------------------------------
    def close(self) -> None:
        """Stop serving, refuse new observations, wait for those being stored and for a running optimization to
        finish its writes, then release the store."""
        with self._state_lock:
            if self._closed:
                return
            self._closed = True
            self._state_lock.wait_for(lambda: self._active == 0)
        self.asks.shutdown()
        with self._planner_lock:
            self.store.close()

    def __enter__(self) -> Campaign:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()
