"""Bad input, fuzzed: random and adversarial payloads on ~/observations. Each gets exactly one event (accepted only
when valid, otherwise rejected with a reason), the node stays up and keeps serving, and the store holds exactly the
valid observations."""

import json
import sqlite3

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



@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
                                 HealthCheck.data_too_large])
@given(data=st.data())
def test_fuzzed_observations(client, start_planner, tmp_path, data):
    """Each example: one drawn adversarial payload (must be rejected), then a valid observation (must be accepted)."""
    state = fuzz_state(client, start_planner, tmp_path)
    proposal = state["fresh"][0]
    bad, (good, _) = adversarial(proposal, state["used"])
    text, _ = data.draw(bad)
    before = len(client.wait_events(0))
    client.publish(text)
    client.publish(good)
    rejected, accepted = client.wait_events(before + 2)[before:]
    assert rejected["type"] == "observation_rejected" and rejected["reason"], (text[:200], rejected)
    assert accepted == {"type": "observation_accepted", "experiment_id": proposal["experiment_id"]}
    state["accepted"].append(state["fresh"].pop(0)["experiment_id"])
    state["used"] = proposal["experiment_id"]
    if not state["fresh"]:
        state["fresh"] = [json.loads(client.recommend().message)["proposals"][0] for _ in range(5)]
    assert client.status()["n_observations"] == len(state["accepted"])
    with sqlite3.connect(state["store"]) as db:
        assert [r[0] for r in db.execute("SELECT experiment_id FROM observations ORDER BY seq")] == state["accepted"]


FUZZ: dict = {}


def fuzz_state(client, start_planner, tmp_path) -> dict:
    """One planner node for all examples (hypothesis reuses the function-scoped fixtures of the first one)."""
    if not FUZZ:
        store = tmp_path / "fuzz.sqlite"
        start_planner(auto_propose=False, storage=str(store))
        client.wait_matched()
        fresh = [json.loads(client.recommend().message)["proposals"][0] for _ in range(5)]
        FUZZ.update(store=store, fresh=fresh, accepted=[], used="no-such-id")
    return FUZZ
