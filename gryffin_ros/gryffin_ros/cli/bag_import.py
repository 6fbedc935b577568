"""`gryffin-ros import BAG --out STORE`: a campaign store rebuilt from a bag the planner node recorded (node parameter
`record`): the campaign's config and seed from the bag's metadata (or --config), then every observation the node
accepted, in the order it accepted them, each checked again against the config as the node checked it. Read with
`rosbags` from the schemas in the bag (no ROS needed). A bad bag is refused with the reason; nothing is written then.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..campaign import Campaign
from ..planner import GryffinRosError
from ..planner.config import read_config

# the keys the planner node writes into metadata.yaml's custom_data (gryffin_ros.nodes.recorder)
CONFIG_KEY, CONFIG_DIR_KEY, SEED_KEY = "gryffin_ros.config", "gryffin_ros.config_dir", "gryffin_ros.seed"
OBSERVATION_TYPE, EVENT_TYPE = "gryffin_ros_msgs/msg/Observation", "gryffin_ros_msgs/msg/Event"


class BagError(GryffinRosError):
    """The bag cannot be read, or holds no campaign this command can rebuild."""


def read_planner_bag(path: Path) -> list[tuple[str, Any]]:
    """[(topic, message)] of the observations and events in a bag, deserialized by rosbags."""
    try:
        from rosbags.highlevel import AnyReader
    except ImportError as exc:
        raise BagError("reading bags needs the 'rosbags' package: install gryffin_ros with its 'record' extra") from exc
    if not path.is_dir():
        raise BagError(f"{path} is not a bag folder (a rosbag2 bag is a folder holding metadata.yaml)")
    if not (path / "metadata.yaml").is_file():
        raise BagError(f"{path} has no metadata.yaml: not a rosbag2 bag")
    try:
        with AnyReader([path]) as reader:
            messages = [(c.topic, reader.deserialize(raw, c.msgtype)) for c, _, raw in reader.messages()
                        if c.msgtype in (OBSERVATION_TYPE, EVENT_TYPE)]
    except BagError:
        raise
    except Exception as exc:  # noqa: BLE001 - rosbags' errors (truncated file, bad schema, ...) with its reason
        raise BagError(f"cannot read the bag {path}: {exc}") from exc
    return messages


def _custom_data(path: Path) -> dict[str, str]:
    import yaml

    try:
        info = yaml.safe_load((path / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    except (OSError, yaml.YAMLError, KeyError, TypeError) as exc:
        raise BagError(f"{path}/metadata.yaml is not rosbag2 metadata: {exc}") from exc
    return dict(info.get("custom_data") or {})


def accepted_observations(messages: list[tuple[str, Any]]) -> list[dict[str, Any]]:
    """The observations the node accepted, as observation items: each received observation is judged by the next
    observation_* event of the same node, in order (the node judges them one at a time)."""
    nodes = sorted({topic.rsplit("/", 1)[0] for topic, msg in messages if topic.endswith("/observations")
                    and hasattr(msg, "objectives")})
    if not nodes:
        raise BagError("the bag holds no typed observations of a planner (topic .../observations)")
    if len(nodes) > 1:
        raise BagError(f"the bag holds the observations of several planners ({', '.join(nodes)}); import each "
                       "from a bag of its own")
    node = nodes[0]
    received = [msg for topic, msg in messages if topic == f"{node}/observations"]
    verdicts = [msg.type for topic, msg in messages if topic == f"{node}/events"
                and msg.type in ("observation_accepted", "observation_rejected")]
    if not verdicts:
        raise BagError(f"the bag holds no events of {node} (topic {node}/events): which observations were accepted "
                       "is unknown")
    items = []
    for msg, verdict in zip(received, verdicts):
        if verdict != "observation_accepted":
            continue
        params = {p.name: (p.text if p.text else p.number) for p in msg.params}
        objectives = None if msg.failed else {o.name: o.value for o in msg.objectives}
        item = {"experiment_id": msg.experiment_id, "params": params, "objectives": objectives}
        if msg.meta_json:
            try:
                item["meta"] = json.loads(msg.meta_json)
            except ValueError:
                pass
        items.append(item)
    return items


def import_bag(bag: str | Path, out: str | Path, config: str | Path | None = None) -> int:
    """Write the campaign of `bag` into the new store `out`; returns the number of observations imported."""
    bag, out = Path(bag), Path(out)
    if out.exists():
        raise BagError(f"{out} exists: import writes a new store (remove it or name another)")
    items = accepted_observations(read_planner_bag(bag))
    custom = _custom_data(bag)
    if config is not None:
        raw, base = read_config(config), Path(config).resolve().parent
    elif custom.get(CONFIG_KEY):
        raw = json.loads(custom[CONFIG_KEY])
        base = Path(custom[CONFIG_DIR_KEY]) if custom.get(CONFIG_DIR_KEY) else None
    else:
        raise BagError(f"the bag {bag} does not hold the campaign's config (not recorded by gryffin_ros "
                       "planner_node?): give it with --config")
    seed = int(custom[SEED_KEY]) if custom.get(SEED_KEY, "").lstrip("-").isdigit() else None
    try:
        with Campaign(raw, out, seed=seed, accept_unsolicited=True, base_dir=base) as campaign:
            for item in items:
                campaign.observe(item, raw=json.dumps(item))
    except BaseException:
        for leftover in (out, Path(f"{out}-wal"), Path(f"{out}-shm"), Path(f"{out}.lock")):
            leftover.unlink(missing_ok=True)
        raise
    return len(items)
