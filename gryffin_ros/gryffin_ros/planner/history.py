"""`History`: what a planner learns from and where its draws stand — the observations in the order they arrived, the
proposals still pending, and the counts of asks and proposals (which, with the seed, make the next proposals
reproducible).

A planner is given its history; it keeps no copy of its own. Used alone (`Planner.ask` / `tell`), a planner owns an
in-memory History that those calls grow. In a `Campaign` the store is the record: the campaign hands the planner a
snapshot of its cache of the store for each proposal and stores what the planner drew before anything counts as
proposed, so a proposal that could not be stored leaves no trace to undo.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from .domain import Observation, Proposal
from .errors import ObservationError


@dataclass
class History:
    observations: list[Observation] = field(default_factory=list)
    pending: dict[str, Proposal] = field(default_factory=dict)
    ask_count: int = 0
    proposal_count: int = 0  # proposals that took a sampling strategy (`BasePlanner.proposal_count`)

    def __post_init__(self) -> None:
        # derived once here and grown with add_observations (a campaign takes a snapshot per observation and reads
        # the failure count with every status: neither walks all the observations again)
        self._ids = {o.experiment_id for o in self.observations if o.experiment_id is not None}
        self._failed = sum(o.failed for o in self.observations)

    @property
    def n_failed(self) -> int:
        """How many of the observations are failed experiments."""
        return self._failed

    def snapshot(self) -> History:
        """A copy whose lists later additions here do not change (the observations themselves are shared)."""
        other = copy.copy(self)
        other.observations, other.pending, other._ids = list(self.observations), dict(self.pending), set(self._ids)
        return other

    def reported(self, experiment_id: str | None) -> bool:
        return experiment_id is not None and experiment_id in self._ids

    def check_new(self, observations: Sequence[Observation]) -> None:
        """ObservationError if an experiment_id was reported before or twice in `observations`."""
        seen = set()
        for o in observations:
            if o.experiment_id is not None:
                if o.experiment_id in self._ids or o.experiment_id in seen:
                    raise ObservationError(f"experiment_id '{o.experiment_id}' was already reported")
                seen.add(o.experiment_id)

    def add_observations(self, observations: Iterable[Observation]) -> None:
        """Observations whose ids are new (`check_new`): appended, and no longer pending."""
        for o in observations:
            self.observations.append(o)
            self._failed += o.failed
            if o.experiment_id is not None:
                self._ids.add(o.experiment_id)
                self.pending.pop(o.experiment_id, None)

    def add_proposals(self, proposals: Iterable[Proposal], ask_count: int, proposal_count: int) -> None:
        """Proposals of one ask, now pending, and the counts after it."""
        self.pending.update((p.experiment_id, p) for p in proposals)
        self.ask_count, self.proposal_count = int(ask_count), int(proposal_count)
