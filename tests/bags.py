"""Reading a recorded bag back with `rosbags` (a reader this project did not write), for the recording tests."""

from __future__ import annotations

from pathlib import Path

from rosbags.highlevel import AnyReader


def read_bag(path: Path) -> list[tuple[str, str, int, object]]:
    """(topic, type, log time in ns, message) of every message in the bag, deserialized by rosbags from the schemas
    the bag carries."""
    with AnyReader([Path(path)]) as reader:
        return [(c.topic, c.msgtype, t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()]


def as_store(msg, objectives: tuple[str, ...]) -> tuple[str, dict, dict]:
    """An Observation message as the store keeps it: (experiment_id, params, objectives; None each when failed)."""
    params = {p.name: (p.text or p.number) for p in msg.params}
    if msg.failed:
        return msg.experiment_id, params, dict.fromkeys(objectives)
    return msg.experiment_id, params, {o.name: o.value for o in msg.objectives}


def judged_observations(messages, node: str = "/gryffin_planner") -> list[tuple[object, str]]:
    """The typed observations the node received, each with the observation_* event the node sent for it (in the
    order of arrival: the node judges them one at a time; one received as the node stopped may have none)."""
    received = [m for topic, _, _, m in messages if topic == f"{node}/observations"]
    events = [m.type for topic, _, _, m in messages if topic == f"{node}/events" and m.type.startswith("observation_")]
    return list(zip(received, events))
