"""ROS 2 node `gryffin_planner`: parses and validates messages, stores observations, calls the Planner, publishes
proposals, events and status. The optimizer runs in its own callback group so topics and ~/get_status stay
responsive while it works.
"""

from __future__ import annotations

import copy
import json
import secrets
import sys
import threading
import time
from pathlib import Path

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import String
from std_srvs.srv import Trigger

from .. import messages
from ..planner import GryffinRosError, Observation, Planner, Proposal
from ..planner.config import load_config, read_config
from ..storage import CampaignStore, StoreError
from .qos import EVENTS_QOS, LATCHED_QOS, OBSERVATIONS_SUBSCRIPTION_QOS, SERVICES_QOS
from .runner import run

PARAMETERS = {
    "config": ("", "path to the campaign config (YAML or JSON; Gryffin format accepted); required"),
    "storage": ("", "SQLite file holding the campaign (default <campaign name>.sqlite); ':memory:' for none"),
    "batch_size": (1, "proposals per recommendation"),
    "acquisition_optimizer": ("", "'adam' (Adam + Hill) or 'genetic'; empty: as the config's general section says"),
    "seed": (-1, "random seed; -1 = random (kept in the store, so a restart continues with it)"),
    "auto_propose": (True, "publish the next proposals as soon as all pending experiments have reported"),
    "accept_unsolicited": (False, "accept observations whose experiment_id this planner never proposed"),
    "max_message_bytes": (messages.MAX_MESSAGE_BYTES, "larger incoming messages are refused unparsed"),
}


REMIND_AFTER_S = 5.0


class StartupError(GryffinRosError):
    """The node cannot start with the parameters and config it was given."""


class Rejected(GryffinRosError):
    """An input the node refuses; the message is the event's reason."""


class PlannerNode(Node):
    def __init__(self) -> None:
        super().__init__("gryffin_planner")
        for name, (default, description) in PARAMETERS.items():
            self.declare_parameter(name, default, ParameterDescriptor(description=description))
        p = {name: self.get_parameter(name).value for name in PARAMETERS}
        if not p["config"]:
            raise StartupError("parameter 'config' is required (path to a YAML or JSON campaign config)")
        if p["batch_size"] < 1:
            raise StartupError(f"parameter 'batch_size' must be at least 1, got {p['batch_size']}")
        if p["acquisition_optimizer"] not in ("", "adam", "genetic"):
            raise StartupError(f"parameter 'acquisition_optimizer' must be 'adam', 'genetic' or empty, got "
                               f"{p['acquisition_optimizer']!r}")
        self.batch_size, self.auto_propose = p["batch_size"], p["auto_propose"]
        self.accept_unsolicited = p["accept_unsolicited"]
        if p["max_message_bytes"] < 1024:
            raise StartupError(f"parameter 'max_message_bytes' must be at least 1024, got {p['max_message_bytes']}")
        self.max_message_bytes = p["max_message_bytes"]

        raw = read_config(p["config"])
        base_dir = Path(p["config"]).resolve().parent
        config = load_config(raw, base_dir)  # validates; its hash identifies the campaign in the store
        storage = p["storage"] or str(Path.cwd() / f"{config.name}.sqlite")
        self.store = CampaignStore(storage, config.raw, config.hash)
        self.campaign = config.name
        seed = p["seed"] if p["seed"] >= 0 else int(self.store.get_meta("seed") or secrets.randbits(63))
        self.store.set_meta("seed", str(seed))
        # node parameters choose how to optimize, not what: they are applied after the campaign hash
        tuned = copy.deepcopy(config.raw)
        if p["acquisition_optimizer"]:
            tuned.setdefault("general", {})["acquisition_optimizer"] = p["acquisition_optimizer"]
        self.planner = self._restore(tuned, seed, base_dir)
        fraction = self.planner.feasible_fraction  # contradictory constraints fail here, before anything starts
        self._warnings = self.planner.constraint_warnings
        for text in self._warnings:
            self.get_logger().warning(text)

        self._planner_lock = threading.Lock()
        self._state_lock = threading.Lock()
        self._inbox: list[Observation] = []
        self._pending = dict(self.planner.pending)  # experiment_id -> Proposal still owed
        self._reported = {o.experiment_id for o in self.planner.observations}
        self._n_failed = sum(o.failed for o in self.planner.observations)
        self._best = self.planner.best()
        self._state = "idle"
        self._ask_blocked = False

        # observations one at a time, in arrival order (so events and the store keep that order); status beside
        optimizer_group, observations_group = MutuallyExclusiveCallbackGroup(), MutuallyExclusiveCallbackGroup()
        status_group = ReentrantCallbackGroup()
        self.proposals_pub = self.create_publisher(String, "~/proposals", LATCHED_QOS)
        self.events_pub = self.create_publisher(String, "~/events", EVENTS_QOS)
        self.status_pub = self.create_publisher(String, "~/status", LATCHED_QOS)
        self.create_subscription(String, "~/observations", self._on_observation, OBSERVATIONS_SUBSCRIPTION_QOS,
                                 callback_group=observations_group)
        self.create_service(Trigger, "~/get_status", self._on_get_status, qos_profile=SERVICES_QOS,
                            callback_group=status_group)
        self.create_service(Trigger, "~/recommend", self._on_recommend, qos_profile=SERVICES_QOS,
                            callback_group=optimizer_group)
        # auto-propose runs when woken (start-up, an accepted observation) instead of polling with a timer
        self._wake = self.create_guard_condition(self._auto_propose, callback_group=optimizer_group)
        # experiments still owed after a quiet spell are announced again (a report may have been lost in a restart)
        self._last_input = time.monotonic()
        self.create_timer(REMIND_AFTER_S / 2, self._remind, callback_group=status_group)
        if self._pending:  # after a restart, the experiments still owed are announced again
            self._publish(self.proposals_pub, messages.proposals_message(
                self.campaign, list(self.planner.pending.values()), len(self.planner.observations)))
        self._publish_status()
        self._wake.trigger()
        self.get_logger().info(
            f"campaign '{self.campaign}' in {storage}: {len(self._reported)} observation(s), {len(self._pending)} "
            f"pending; feasible fraction {fraction.value:.3g} ({fraction.method}); seed {seed}; acquisition optimizer "
            f"{self.planner.config.general.acquisition_optimizer}")

    def _restore(self, config: dict, seed: int, base_dir: Path) -> Planner:
        proposals = self.store.proposals()
        observations = self.store.observations()
        reported = {o.experiment_id for o in observations}
        state = {
            "format": 1, "strategy": "Planner", "config": config, "seed": seed,
            "observations": [o.to_dict() for o in observations],
            "pending": [p.to_dict() for p in proposals if p.experiment_id not in reported],
            "ask_count": int(self.store.get_meta("ask_count") or 0),
            "proposal_count": int(self.store.get_meta("proposal_count") or 0),
        }
        return Planner.from_state(state, base_dir=base_dir)

    # ---- outputs ---------------------------------------------------------------------------------------------
    def _publish(self, publisher, text: str) -> None:
        publisher.publish(String(data=text))

    def _event(self, kind: str, experiment_id: str | None = None, reason: str | None = None) -> None:
        event = {"type": kind}
        if experiment_id is not None:
            event["experiment_id"] = experiment_id
        if reason is not None:
            event["reason"] = reason
        self._publish(self.events_pub, messages.dump("event", event))

    def status(self) -> dict:
        with self._state_lock:
            best = self._best
            return {
                "campaign": self.campaign, "n_observations": len(self._reported), "n_pending": len(self._pending),
                "n_failed": self._n_failed, "state": self._state,
                "best": None if best is None else {"experiment_id": best.experiment_id, "params": best.params,
                                                   "objectives": best.objectives},
                "warnings": list(self._warnings),
            }

    def _publish_status(self) -> None:
        self._publish(self.status_pub, messages.dump("status", self.status()))

    # ---- inputs ----------------------------------------------------------------------------------------------
    def _on_observation(self, msg: String) -> None:
        try:
            items = messages.observation_items(messages.parse("observation", msg.data, self.max_message_bytes))
        except GryffinRosError as exc:
            self._event("observation_rejected", reason=str(exc))
            return
        except Exception as exc:  # whatever a sender manages to trigger, the node stays up and says so
            self.get_logger().error(f"internal error parsing an observation message: {exc!r}")
            self._event("observation_rejected", reason=f"internal error: {exc!r}")
            return
        for item in items:
            try:
                self._accept(item)
            except Exception as exc:  # a bug must not take the node down with the lab's data
                self.get_logger().error(f"internal error on observation {item.get('experiment_id')}: {exc!r}")
                self._event("observation_rejected", item.get("experiment_id"), f"internal error: {exc!r}")
        self._publish_status()

    def _accept(self, item: dict) -> None:
        experiment_id = item["experiment_id"]
        try:
            observation = self.planner.parse_observation(item)
            with self._state_lock:
                if experiment_id in self._reported:
                    raise Rejected(f"experiment_id '{experiment_id}' was already reported; the first report stands")
                if experiment_id not in self._pending and not self.accept_unsolicited:
                    raise Rejected(f"unknown experiment_id '{experiment_id}': this planner did not propose it (set "
                                   "accept_unsolicited to accept prior data)")
                self._reported.add(experiment_id)
            try:
                self.store.add_observation(observation, raw=json.dumps(item))
            except StoreError:
                with self._state_lock:
                    self._reported.discard(experiment_id)
                raise
        except GryffinRosError as exc:
            self._event("observation_rejected", experiment_id, str(exc))
            return
        with self._state_lock:
            self._last_input = time.monotonic()
            self._inbox.append(observation)
            self._pending.pop(experiment_id, None)
            self._n_failed += observation.failed
            self._ask_blocked = False
        self._event("observation_accepted", experiment_id)
        self._wake.trigger()
        # the planner learns it now unless it is busy optimizing; then right after (never block on it here)
        if self._planner_lock.acquire(blocking=False):
            try:
                self._absorb()
            finally:
                self._planner_lock.release()

    def _absorb(self) -> None:
        """Tell the planner the observations accepted since last time (caller holds the planner lock)."""
        with self._state_lock:
            inbox, self._inbox = self._inbox, []
        if inbox:
            self.planner.tell(inbox)
            best = self.planner.best()
            with self._state_lock:
                self._best = best

    def _remind(self) -> None:
        with self._state_lock:
            owed = list(self._pending.values())
            quiet = time.monotonic() - self._last_input > REMIND_AFTER_S
            if quiet:
                self._last_input = time.monotonic()
        if owed and quiet and self.auto_propose:
            self._publish(self.proposals_pub, messages.proposals_message(self.campaign, owed, len(self._reported)))

    def _on_get_status(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        response.success, response.message = True, messages.dump("status", self.status())
        return response

    # ---- optimizer (its own callback group) ------------------------------------------------------------------
    def _propose(self) -> list[Proposal]:
        with self._planner_lock:
            with self._state_lock:
                self._state = "optimizing"
            self._publish_status()
            try:
                self._absorb()
                proposals = self.planner.ask(self.batch_size)
                self.store.add_proposals(proposals, {"ask_count": str(self.planner.ask_count),
                                                     "proposal_count": str(self.planner.proposal_count)})
            except Exception as exc:
                with self._state_lock:
                    self._state, self._ask_blocked = "error", True
                if not isinstance(exc, GryffinRosError):  # a bug: report it, keep the node and the data alive
                    self.get_logger().error(f"internal error while proposing: {exc!r}")
                    exc = GryffinRosError(f"internal error: {exc!r}")
                self._event("error", reason=str(exc))
                self._publish_status()
                raise exc
            with self._state_lock:
                self._pending.update((p.experiment_id, p) for p in proposals)
                self._state = "idle"
            self._absorb()  # what arrived while optimizing
        self._event("proposals_ready", reason=f"{len(proposals)} proposal(s) after "
                                              f"{len(self.planner.observations)} observation(s)")
        self._publish_status()
        return proposals

    def _auto_propose(self) -> None:
        with self._state_lock:
            due = self.auto_propose and not self._pending and not self._ask_blocked
        if not due:
            return
        try:
            proposals = self._propose()
        except GryffinRosError:
            return
        self._publish(self.proposals_pub, messages.proposals_message(
            self.campaign, proposals, len(self.planner.observations)))

    def _on_recommend(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        try:
            proposals = self._propose()
        except GryffinRosError as exc:
            response.success = False
            response.message = messages.dump("error", {"error": type(exc).__name__, "reason": str(exc)})
            return response
        response.success = True
        response.message = messages.proposals_message(self.campaign, proposals, len(self.planner.observations))
        return response


def close_store(node: PlannerNode) -> None:
    with node._planner_lock:  # an optimizer callback still running finishes its writes first
        node.store.close()


def main(args: list[str] | None = None) -> int:
    return run(PlannerNode, "gryffin_planner", args, lambda: MultiThreadedExecutor(num_threads=4), close_store)


if __name__ == "__main__":
    sys.exit(main())
