"""The wire contract: every schema is valid, its examples pass, and bad payloads get specific reasons."""

import json

import pytest

from gryffin_ros import messages
from gryffin_ros.paths import share_path


@pytest.mark.parametrize("name", messages.SCHEMAS)
def test_schema_examples_validate(name):
    schema = json.loads((share_path("msg_schemas") / f"{name}.schema.json").read_text())
    assert schema["examples"], f"{name} schema has no example"
    for example in schema["examples"]:
        messages.check(name, example)


# What the reason must say: ours (where, and the field concerned), not jsonschema's wording around the field's name,
# which is a third-party library's and may change with its version.
@pytest.mark.parametrize("text, reason", [
    ("[1, 2", ["malformed JSON"]),
    ('{"experiment_id": "a", "params": {"x": NaN}, "objectives": null}', ["NaN is not valid JSON"]),
    ('{"experiment_id": "a", "params": {"x": 1}}', ["invalid at (root)", "'objectives'"]),
    ('{"experiment_id": "a", "params": {"x": [1]}, "objectives": null}', ["invalid at params/x"]),
    ('{"experiment_id": "a", "params": {"x": 1}, "objectives": null, "extra": 1}', ["invalid at (root)", "'extra'"]),
    ("[]", ["invalid"]),
])
def test_bad_observation_payloads_are_refused_with_a_reason(text, reason):
    with pytest.raises(messages.MessageError) as info:
        messages.parse("observation", text)
    assert all(part in str(info.value) for part in reason), str(info.value)


def test_oversized_message_is_refused_before_parsing():
    with pytest.raises(messages.MessageError, match="larger than"):
        messages.parse("observation", '"' + "x" * (messages.MAX_MESSAGE_BYTES + 1) + '"')


def test_outgoing_payloads_are_checked_too():
    with pytest.raises(messages.MessageError):
        messages.dump("event", {"type": "something_else"})


def test_proposals_carry_how_they_were_chosen():
    from gryffin_ros.planner import Proposal
    proposal = Proposal("e1", {"x": 0.5}, None, {"surrogate": "gp", "loo_rank_correlation": {"kde": 0.1, "gp": 0.8}})
    document = json.loads(messages.proposals_message("c", [proposal], 7))
    assert document["proposals"][0]["meta"]["surrogate"] == "gp"
    with pytest.raises(messages.MessageError):  # meta must be an object
        messages.dump("proposals", {**document, "proposals": [{**document["proposals"][0], "meta": "gp"}]})
