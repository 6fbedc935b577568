"""Bad input, fuzzed: random and adversarial payloads on ~/observations. Each gets exactly one event (accepted only
when valid, otherwise rejected with a reason), the node stays up and keeps serving, and the store holds exactly the
valid observations."""

import json
import sqlite3

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

PARAMS = ("F_C", "F_S", "T")


def adversarial(proposal: dict, used: str) -> tuple[st.SearchStrategy, tuple[str, bool]]:
    """Invalid (payload text, False) pairs built around one unused proposal and one already reported
    experiment_id, and the valid observation of that proposal."""
    eid, params = proposal["experiment_id"], proposal["params"]

    def obs(**changes):
        return {"experiment_id": eid, "params": dict(params), "objectives": {"X1_X2": 0.5}, **changes}

    numbers = st.one_of(st.floats(allow_nan=False, allow_infinity=False, width=32), st.integers(-10**30, 10**30))
    bad = st.one_of(
        st.text(max_size=50).map(lambda t: (t, False)),  # arbitrary text, almost never an observation
        st.just(("{" * 5000 + "}" * 5000, False)),  # deeply nested
        st.just(("[" * 200 + "]" * 200, False)),
        st.just(('"' + "x" * (2 * 1024 * 1024) + '"', False)),  # over max_message_bytes
        st.just((json.dumps(obs()).replace("0.5", "NaN"), False)),
        st.just((json.dumps(obs()).replace("0.5", "1e400"), False)),  # JSON infinity
        st.sampled_from(PARAMS).map(lambda k: (json.dumps(obs(params={**params, k: "hot"})), False)),
        numbers.filter(lambda v: not 0 <= v <= 150).map(
            lambda v: (json.dumps(obs(params={**params, "T": v})), False)),  # T out of [100, 150]
        st.just((json.dumps(obs(params={**params, "F_C": 199.0, "F_S": 1.0})), False)),  # infeasible
        st.just((json.dumps(obs(params={**params, "pressure": 1.0})), False)),
        st.just((json.dumps({k: v for k, v in obs().items() if k != "params"}), False)),
        st.just((json.dumps({**obs(), "experiment_id": "never-proposed"}), False)),
        st.just((json.dumps({**obs(), "experiment_id": used}), False)),  # duplicate
        st.just((json.dumps({**obs(), "objectives": {"X1_X2": [1]}}), False)),
        st.just((json.dumps({**obs(), "extra": {"a": 1}}), False)),
        st.just(("null", False)),
        st.just(("[]", False)),
    )
    return bad, (json.dumps(obs()), True)


@pytest.fixture
def fuzz_store(client, start_planner, tmp_path):
    """One planner node for all examples of a run (hypothesis sets up function-scoped fixtures once per test, not once
    per example); its store."""
    store = tmp_path / "fuzz.sqlite"
    start_planner(auto_propose=False, storage=str(store))
    client.wait_matched()
    return store


def stored_ids(store) -> list[str]:
    with sqlite3.connect(store) as db:
        return [r[0] for r in db.execute("SELECT experiment_id FROM observations ORDER BY seq")]


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
                                 HealthCheck.data_too_large])
@given(data=st.data())
def test_fuzzed_observations(client, fuzz_store, data):
    """Each example: one drawn adversarial payload (must be rejected), then a valid observation (must be accepted).
    An example takes what it needs from the node and its store, not from earlier examples, and checks only what it
    changed, so a replayed or shrunk example means the same as in the run that found it."""
    (proposal,) = json.loads(client.recommend().message)["proposals"]  # the node keeps serving
    stored_before = stored_ids(fuzz_store)
    used = stored_before[-1] if stored_before else "no-such-id"  # an already reported experiment_id
    bad, (good, _) = adversarial(proposal, used)
    text, _ = data.draw(bad)
    observations_before = client.status()["n_observations"]
    before = len(client.wait_events(0))
    client.publish(text)
    client.publish(good)
    rejected, accepted = client.wait_events(before + 2)[before:]
    assert rejected["type"] == "observation_rejected" and rejected["reason"], (text[:200], rejected)
    assert accepted == {"type": "observation_accepted", "experiment_id": proposal["experiment_id"]}
    assert client.status()["n_observations"] == observations_before + 1
    assert stored_ids(fuzz_store) == [*stored_before, proposal["experiment_id"]]
