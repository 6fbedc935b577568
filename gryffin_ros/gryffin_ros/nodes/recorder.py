"""A campaign recorded as a ROS 2 bag (node parameter `record`): every typed message the planner publishes or
accepts, CDR-serialized by rclpy exactly as on the wire, with the ROS 2 message definitions as schemas, the topic
names as on the wire and the time the node received (or sent) it, in the rosbag2 layout: a folder holding
`metadata.yaml` and MCAP files (`<folder name>_<n>.mcap`), readable by rosbag2, `rosbags`, Foxglove.

Crash safety: an MCAP file is only readable with its summary and footer, which a writer adds when it closes. So the
recorder keeps the messages of its current file in memory and, at most one second after a message arrived, writes
that file again in full (a new file, then renamed over the old one) and `metadata.yaml` with it: whatever ends the
process, SIGKILL included, the bag on disk is complete and loses at most the last second. A file is closed for good
after `SEGMENT_MESSAGES` messages and the next one started (rosbag2's split bag), so rewriting stays cheap.
"""

from __future__ import annotations

import importlib
import json
import os
import re
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message

from ..planner import GryffinRosError

# metadata.yaml custom_data keys of a planner's bag (`gryffin-ros import` reads them)
CONFIG_KEY, CONFIG_DIR_KEY, SEED_KEY = "gryffin_ros.config", "gryffin_ros.config_dir", "gryffin_ros.seed"
SEGMENT_MESSAGES = 2000
FLUSH_S = 1.0
BAG_VERSION = 9
SEPARATOR = "=" * 80
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32",
              "int64", "uint64", "string", "wstring"}


def type_name(msg: Any) -> str:
    """`pkg/msg/Name` of a generated message instance."""
    module = type(msg).__module__.split(".")
    return f"{module[0]}/msg/{type(msg).__name__}"


def _msg_file(name: str) -> Path:
    """The .msg file rosidl installed for `pkg/msg/Name`: under the package's share folder found by the ament index
    (a sourced workspace), else under the prefix its Python package is installed in (the wheels' environment needs no
    AMENT_PREFIX_PATH)."""
    package, _, short = name.split("/")
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    try:
        module = Path(importlib.import_module(package).__file__).resolve()
        prefixes.append(str(module.parents[4]))  # <prefix>/lib/pythonX.Y/site-packages/<package>/__init__.py
    except (ImportError, IndexError, TypeError):
        pass
    prefixes.append(sys.prefix)
    for prefix in prefixes:
        candidate = Path(prefix) / "share" / package / "msg" / f"{short}.msg"
        if candidate.is_file():
            return candidate
    raise GryffinRosError(f"cannot record {name}: its definition msg/{short}.msg is not in the share folder of "
                          f"{package} under any of {', '.join(prefixes)}")


def _dependencies(text: str, package: str) -> list[str]:
    found = []
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line or "=" in line.split()[0] or len(line.split()) < 2:
            continue
        kind = re.sub(r"\[.*\]$", "", line.split()[0])
        kind = re.sub(r"<=\d+$", "", kind)
        if kind in PRIMITIVES or "=" in line.split()[1]:
            continue
        if "/" in kind:
            parts = kind.split("/")
            found.append(f"{parts[0]}/msg/{parts[-1]}")
        else:
            found.append(f"{package}/msg/{kind}")
    return found


def message_definition(name: str) -> str:
    """The `ros2msg` schema rosbag2 writes: the type's .msg text, then each type it uses (depth first), each after
    a line of 80 '=' and `MSG: pkg/Name`."""
    main = _msg_file(name).read_text()
    seen, parts, todo = {name}, [main], list(_dependencies(main, name.split("/")[0]))
    while todo:
        dependency = todo.pop(0)
        if dependency in seen:
            continue
        seen.add(dependency)
        text = _msg_file(dependency).read_text()
        package, _, short = dependency.split("/")
        parts.append(f"{SEPARATOR}\nMSG: {package}/{short}\n{text}")
        todo.extend(_dependencies(text, package))
    return "\n".join(part.rstrip("\n") for part in parts) + "\n"


def type_hash(name: str) -> str:
    """The type's RIHS01 hash, as rosidl generated it (share/<pkg>/msg/<Name>.json); empty when not there."""
    path = _msg_file(name).with_suffix(".json")
    try:
        hashes = json.loads(path.read_text()).get("type_hashes", [])
    except (OSError, ValueError):
        return ""
    return next((h["hash_string"] for h in hashes if h.get("type_name") == name), "")


def qos_yaml(qos: QoSProfile) -> str:
    """offered_qos_profiles as rosbag2 (metadata version 9) writes them."""
    def duration(d) -> dict[str, int]:
        ns = d.nanoseconds
        return {"sec": ns // 10**9, "nsec": ns % 10**9}
    profile = {"history": qos.history.name.lower(), "depth": qos.depth,
               "reliability": qos.reliability.name.lower(), "durability": qos.durability.name.lower(),
               "deadline": duration(qos.deadline), "lifespan": duration(qos.lifespan),
               "liveliness": qos.liveliness.name.lower(),
               "liveliness_lease_duration": duration(qos.liveliness_lease_duration),
               "avoid_ros_namespace_conventions": qos.avoid_ros_namespace_conventions}
    return yaml.safe_dump([profile], sort_keys=False)


@dataclass
class _Topic:
    name: str
    type: str
    qos: str
    definition: str
    hash: str
    count: int = 0


@dataclass
class _Segment:
    path: Path
    messages: list[tuple[str, int, bytes]] = field(default_factory=list)  # topic, receive time (ns), CDR
    start_ns: int | None = None
    end_ns: int = 0


# what the planner node records with `record`: its typed outputs and both kinds of observation input
PLANNER_TYPES = ("gryffin_ros_msgs/msg/Proposals", "gryffin_ros_msgs/msg/Event", "gryffin_ros_msgs/msg/CampaignStatus",
                 "gryffin_ros_msgs/msg/Observation", "std_msgs/msg/String")


def campaign_recorder(path: str, config: str, store_config: str, seed: int) -> BagRecorder:
    """The planner node's recorder: its message types, and in metadata.yaml what `gryffin-ros import` needs to make
    a store of the bag again (the stored config, the seed, the config's folder for its relative file names)."""
    return BagRecorder(path, custom_data={CONFIG_KEY: store_config, SEED_KEY: str(seed),
                                          CONFIG_DIR_KEY: str(Path(config).resolve().parent)}, types=PLANNER_TYPES)


class BagRecorder:
    """Records messages into the bag folder `path` (which must not exist yet); `close` finishes it."""

    def __init__(self, path: str | os.PathLike, flush_s: float = FLUSH_S, segment_messages: int = SEGMENT_MESSAGES,
                 custom_data: dict[str, str] | None = None, types: tuple[str, ...] = ()):
        try:
            import mcap.writer  # noqa: F401 - the `record` extra
        except ImportError as exc:
            raise GryffinRosError("recording needs the 'mcap' package: install gryffin_ros with its 'record' "
                                  "extra") from exc
        self.path = Path(path)
        # the schemas of the types to be recorded, looked up now: a missing definition fails here, not mid-campaign
        self._definitions = {name: (message_definition(name), type_hash(name)) for name in types}
        if self.path.exists():
            raise GryffinRosError(f"record: {self.path} already exists (a bag is never overwritten; name a new "
                                  "folder)")
        if not self.path.parent.is_dir():
            raise GryffinRosError(f"record: the folder {self.path.parent} does not exist")
        self.path.mkdir()
        self._segment_messages = segment_messages
        # metadata.yaml's custom_data (strings): the planner keeps its config there, so a bag can become a store
        self._custom_data = {"recorded_by": "gryffin_ros planner_node", **(custom_data or {})}
        self._topics: dict[str, _Topic] = {}
        self._sealed: list[_Segment] = []
        self._failure: str | None = None
        self._segment = self._new_segment()
        self._lock = threading.Lock()
        self._dirty = True
        self._closed = threading.Event()
        self._flush_s = flush_s
        self._write()  # an empty but valid bag from the start
        self._thread = threading.Thread(target=self._flusher, name="bag-recorder", daemon=True)
        self._thread.start()

    def _new_segment(self) -> _Segment:
        return _Segment(self.path / f"{self.path.name}_{len(self._sealed)}.mcap")

    def record(self, topic: str, msg: Any, qos: QoSProfile, receive_ns: int | None = None) -> None:
        """Keep `msg` as sent or received on `topic` (its resolved name) now or at `receive_ns`."""
        if self._closed.is_set():
            return
        stamp = time.time_ns() if receive_ns is None else receive_ns
        data = serialize_message(msg)
        with self._lock:
            if topic not in self._topics:
                name = type_name(msg)
                if name not in self._definitions:
                    self._definitions[name] = (message_definition(name), type_hash(name))
                self._topics[topic] = _Topic(topic, name, qos_yaml(qos), *self._definitions[name])
            self._topics[topic].count += 1
            segment = self._segment
            segment.messages.append((topic, stamp, data))
            segment.start_ns = stamp if segment.start_ns is None else min(segment.start_ns, stamp)
            segment.end_ns = max(segment.end_ns, stamp)
            self._dirty = True
            if len(segment.messages) >= self._segment_messages:
                self._write_locked()
                self._sealed.append(segment)
                self._segment = self._new_segment()

    def _flusher(self) -> None:
        while not self._closed.wait(self._flush_s):
            try:
                self.flush()
            except Exception as exc:  # noqa: BLE001 - a full disk: said once, tried again each second
                if self._failure is None:
                    print(f"record: writing {self.path} failed ({exc!r}); retrying every {self._flush_s} s",
                          file=sys.stderr, flush=True)
                self._failure = repr(exc)
            else:
                self._failure = None

    def flush(self) -> None:
        with self._lock:
            if self._dirty:
                self._write_locked()

    def close(self) -> None:
        if self._closed.is_set():
            return
        self._closed.set()
        self._thread.join()
        self.flush()

    def _write(self) -> None:
        with self._lock:
            self._write_locked()

    def _write_locked(self) -> None:
        from mcap.writer import CompressionType, Writer

        segment = self._segment
        tmp = segment.path.with_name(segment.path.name + ".tmp")
        with open(tmp, "wb") as stream:
            writer = Writer(stream, compression=CompressionType.ZSTD)
            writer.start(profile="ros2", library="gryffin_ros")
            channels: dict[str, int] = {}
            for topic in dict.fromkeys(t for t, _, _ in segment.messages):
                info = self._topics[topic]
                schema = writer.register_schema(info.type, "ros2msg", info.definition.encode())
                channels[topic] = writer.register_channel(topic, "cdr", schema,
                                                          {"offered_qos_profiles": info.qos})
            for sequence, (topic, stamp, data) in enumerate(segment.messages):
                writer.add_message(channels[topic], log_time=stamp, data=data, publish_time=stamp,
                                   sequence=sequence)
            writer.finish()
        os.replace(tmp, segment.path)
        self._write_metadata()
        self._dirty = False

    def _write_metadata(self) -> None:
        segments = [*self._sealed, self._segment]
        starts = [s.start_ns for s in segments if s.start_ns is not None]
        start = min(starts) if starts else 0
        end = max((s.end_ns for s in segments), default=0)
        info = {
            "version": BAG_VERSION,
            "storage_identifier": "mcap",
            "relative_file_paths": [s.path.name for s in segments],
            "duration": {"nanoseconds": max(0, end - start)},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": sum(len(s.messages) for s in segments),
            "topics_with_message_count": [
                {"topic_metadata": {"name": t.name, "type": t.type, "serialization_format": "cdr",
                                    "offered_qos_profiles": yaml.safe_load(t.qos), "type_description_hash": t.hash},
                 "message_count": t.count}
                for t in self._topics.values()],
            "compression_format": "",
            "compression_mode": "",
            "files": [{"path": s.path.name, "starting_time": {"nanoseconds_since_epoch": s.start_ns or 0},
                       "duration": {"nanoseconds": max(0, s.end_ns - (s.start_ns or 0))},
                       "message_count": len(s.messages)} for s in segments],
            "custom_data": self._custom_data,
            "ros_distro": "jazzy",
        }
        tmp = self.path / "metadata.yaml.tmp"
        tmp.write_text(yaml.safe_dump({"rosbag2_bagfile_information": info}, sort_keys=False))
        os.replace(tmp, self.path / "metadata.yaml")
