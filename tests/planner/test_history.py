"""A planner's History: what a snapshot shares and what it does not, and the counts it keeps as it grows."""

import pytest

from gryffin_ros.planner import Observation, ObservationError, Proposal
from gryffin_ros.planner.history import History


def test_a_snapshot_keeps_its_own_observations_ids_pending_and_failure_count():
    history = History([Observation({"x": 1.0}, {"y": None}, "a")], {"p": Proposal("p", {"x": 2.0})}, 1, 1)
    snapshot = history.snapshot()
    history.add_observations([Observation({"x": 2.0}, {"y": None}, "p")])
    snapshot.add_observations([Observation({"x": 3.0}, {"y": 0.5}, "c")])
    assert [o.experiment_id for o in history.observations] == ["a", "p"] and history.pending == {}
    assert [o.experiment_id for o in snapshot.observations] == ["a", "c"] and set(snapshot.pending) == {"p"}
    assert (history.n_failed, snapshot.n_failed) == (2, 1)
    assert history.reported("p") and not snapshot.reported("p")
    assert snapshot.reported("c") and not history.reported("c")
    with pytest.raises(ObservationError, match="'a' was already reported"):
        snapshot.check_new([Observation({"x": 4.0}, {"y": 1.0}, "a")])
