"""ROS 2 node `gryffin_planner`: translates messages to and from a `Campaign` (which owns the store, the planner and
the bookkeeping) and publishes proposals, events and status. The optimizer runs in its own callback group so topics
and ~/get_status stay responsive while it works.
"""

from __future__ import annotations

import json
import sys
import threading
import time
from pathlib import Path

from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import String
from std_srvs.srv import Trigger

from .. import messages
from ..campaign import Campaign
from ..planner import GryffinRosError, Proposal
from ..planner.config import read_config
from .qos import EVENTS_QOS, LATCHED_QOS, OBSERVATIONS_SUBSCRIPTION_QOS, SERVICES_QOS
from .runner import declare, run

PARAMETERS = {
    "config": ("", "path to the campaign config (YAML or JSON; Gryffin format accepted); required"),
    "storage": ("", "SQLite file holding the campaign (default <campaign name>.sqlite); ':memory:' for none"),
    "batch_size": (1, "proposals per recommendation"),
    "acquisition_optimizer": ("", "'adam' (Adam + Hill) or 'genetic'; empty: as the config's general section says"),
    "seed": (-1, "random seed; -1 = random (kept in the store, so a restart continues with it)"),
    "auto_propose": (True, "publish the next proposals as soon as all pending experiments have reported"),
    "accept_unsolicited": (False, "accept observations whose experiment_id this planner never proposed"),
    "max_message_bytes": (messages.MAX_MESSAGE_BYTES, "larger incoming messages are refused unparsed"),
    "dashboard_port": (-1, "serve the campaign's live web page on this port (0: any free port; -1: none)"),
    "dashboard_host": ("127.0.0.1", "address the web page binds to (default: this machine only)"),
}


REMIND_AFTER_S = 5.0


class StartupError(GryffinRosError):
    """The node cannot start with the parameters and config it was given."""


class PlannerNode(Node):
    def __init__(self) -> None:
        super().__init__("gryffin_planner")
        p = declare(self, PARAMETERS)
        if not p["config"]:
            raise StartupError("parameter 'config' is required (path to a YAML or JSON campaign config)")
        if p["batch_size"] < 1:
            raise StartupError(f"parameter 'batch_size' must be at least 1, got {p['batch_size']}")
        if p["acquisition_optimizer"] not in ("", "adam", "genetic"):
            raise StartupError(f"parameter 'acquisition_optimizer' must be 'adam', 'genetic' or empty, got "
                               f"{p['acquisition_optimizer']!r}")
        self.batch_size, self.auto_propose = p["batch_size"], p["auto_propose"]
        if p["max_message_bytes"] < 1024:
            raise StartupError(f"parameter 'max_message_bytes' must be at least 1024, got {p['max_message_bytes']}")
        self.max_message_bytes = p["max_message_bytes"]

        # default store: <campaign name>.sqlite here (the name is validated with the rest of the config below)
        storage = p["storage"] or f"{read_config(p['config']).get('name', 'campaign')}.sqlite"
        # node parameters choose how to optimize, not what: they do not change the campaign's identity
        settings = {"acquisition_optimizer": p["acquisition_optimizer"]} if p["acquisition_optimizer"] else None
        self.campaign = Campaign(p["config"], storage, seed=p["seed"] if p["seed"] >= 0 else None, settings=settings,
                                 accept_unsolicited=p["accept_unsolicited"])
        try:
            fraction = self.campaign.planner.feasible_fraction  # contradictory constraints fail here, at start-up
        except BaseException:
            self.campaign.close()
            raise
        for text in self.campaign.warnings:
            self.get_logger().warning(text)
        self.dashboard = None
        if p["dashboard_port"] >= 0:
            self.dashboard = self._start_dashboard(storage, p["dashboard_host"], p["dashboard_port"], p["config"])
        self._closing = False
        self._ask_blocked = False  # an ask failed; wait for new data before auto-proposing again
        self._flag_lock = threading.Lock()

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
        owed = self.campaign.pending
        if owed:  # after a restart, the experiments still owed are announced again, to whoever takes them
            self.campaign.mark_unclaimed()
            self._publish(self.proposals_pub, messages.proposals_message(
                self.campaign.name, owed, self.campaign.n_observations))
        self._publish_status()
        self._wake.trigger()
        self.get_logger().info(
            f"campaign '{self.campaign.name}' in {storage}: {self.campaign.n_observations} observation(s), "
            f"{len(owed)} pending; feasible fraction {fraction.value:.3g} ({fraction.method}); seed "
            f"{self.campaign.seed}; acquisition optimizer {self.campaign.config.general.acquisition_optimizer}")

    def _start_dashboard(self, storage: str, host: str, port: int, config: str):
        from ..dashboard import start  # the web server and plotly load only when asked for
        try:
            if storage == ":memory:":
                raise StartupError("parameter 'dashboard_port': the dashboard reads the campaign store; give "
                                   "'storage' a file")
            server = start(storage, host, port, Path(config).resolve().parent)
        except BaseException as exc:
            self.campaign.close()
            if isinstance(exc, GryffinRosError) and not isinstance(exc, StartupError):
                raise StartupError(f"parameter 'dashboard_port': {exc}") from None
            raise
        self.get_logger().info(f"dashboard: {server.url}")
        if not server.loopback:
            self.get_logger().warning(f"dashboard on {host}: reachable from other machines, without authentication")
        return server

    # ---- outputs ---------------------------------------------------------------------------------------------
    def _publish(self, publisher, text: str) -> None:
        if self._closing:  # nothing is published once shutdown has begun (the context may be gone)
            return
        try:
            publisher.publish(String(data=text))
        except Exception:  # noqa: BLE001 - shutdown began while this callback was running
            if not self._closing:
                raise

    def _event(self, kind: str, experiment_id: str | None = None, reason: str | None = None) -> None:
        event = {"type": kind}
        if experiment_id is not None:
            event["experiment_id"] = experiment_id
        if reason is not None:
            event["reason"] = reason
        self._publish(self.events_pub, messages.dump("event", event))

    def status(self) -> dict:
        return self.campaign.status()

    def _publish_status(self) -> None:
        self._publish(self.status_pub, messages.dump("status", self.status()))

    # ---- inputs ----------------------------------------------------------------------------------------------
    def _on_observation(self, msg: String) -> None:
        try:
            items = messages.observation_items(messages.parse("observation", msg.data, self.max_message_bytes))
        except GryffinRosError as exc:
            self._event("observation_rejected", reason=str(exc))
            self.campaign.reject(str(exc), msg.data)
            return
        except Exception as exc:  # whatever a sender manages to trigger, the node stays up and says so
            self.get_logger().error(f"internal error parsing an observation message: {exc!r}")
            self._event("observation_rejected", reason=f"internal error: {exc!r}")
            return
        for item in items:
            # the store keeps the message as it arrived; of a batch, each observation's own part
            raw = msg.data if len(items) == 1 else json.dumps(item)
            try:
                self.campaign.observe(item, raw=raw)
            except GryffinRosError as exc:
                self._event("observation_rejected", item.get("experiment_id"), str(exc))
                continue
            except Exception as exc:  # a bug must not take the node down with the lab's data
                self.get_logger().error(f"internal error on observation {item.get('experiment_id')}: {exc!r}")
                self._event("observation_rejected", item.get("experiment_id"), f"internal error: {exc!r}")
                continue
            with self._flag_lock:
                self._last_input = time.monotonic()
                self._ask_blocked = False
            self._event("observation_accepted", item["experiment_id"])
            self._wake.trigger()
        self._publish_status()

    def _remind(self) -> None:
        with self._flag_lock:
            quiet = time.monotonic() - self._last_input > REMIND_AFTER_S
            if quiet:
                self._last_input = time.monotonic()
        owed = self.campaign.pending if quiet and self.auto_propose else []
        if owed:
            self._publish(self.proposals_pub, messages.proposals_message(self.campaign.name, owed,
                                                                         self.campaign.n_observations))

    def _on_get_status(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        response.success, response.message = True, messages.dump("status", self.status())
        return response

    # ---- optimizer (its own callback group) ------------------------------------------------------------------
    def _run(self, make) -> list[Proposal]:
        """Run `make(started)` (which proposes and calls `started` once optimizing), reporting status and errors; a
        failure is raised as GryffinRosError."""
        try:
            proposals = make(self._publish_status)
        except Exception as exc:
            with self._flag_lock:
                self._ask_blocked = True
            if not isinstance(exc, GryffinRosError):  # a bug: report it, keep the node and the data alive
                self.get_logger().error(f"internal error while proposing: {exc!r}")
                exc = GryffinRosError(f"internal error: {exc!r}")
            self._event("error", reason=str(exc))
            self._publish_status()
            raise exc
        self._event("proposals_ready", reason=f"{len(proposals)} proposal(s) after "
                                              f"{self.campaign.n_observations} observation(s)")
        self._publish_status()
        return proposals

    def _auto_propose(self) -> None:
        with self._flag_lock:
            due = self.auto_propose and not self._ask_blocked and not self._closing
        if not due or self.campaign.pending:
            return
        try:
            proposals = self._run(lambda started: self.campaign.propose(self.batch_size, False, started))
        except GryffinRosError:
            return
        self._publish(self.proposals_pub, messages.proposals_message(
            self.campaign.name, proposals, self.campaign.n_observations))

    def _on_recommend(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        try:
            proposals = self._run(lambda started: self.campaign.claim(self.batch_size, started))
        except GryffinRosError as exc:
            response.success = False
            response.message = messages.dump("error", {"error": type(exc).__name__, "reason": str(exc)})
            return response
        response.success = True
        response.message = messages.proposals_message(self.campaign.name, proposals, self.campaign.n_observations)
        return response

    def begin_shutdown(self) -> None:
        """Stop publishing and auto-proposing (observations arriving meanwhile are still stored, until close)."""
        self._closing = True

    def close(self) -> None:
        """Release the campaign, after observations being stored and a running optimization are done."""
        self._closing = True
        if self.dashboard is not None:
            self.dashboard.close()
        self.campaign.close()


def main(args: list[str] | None = None) -> int:
    return run(PlannerNode, "gryffin_planner", args, lambda: MultiThreadedExecutor(num_threads=4),
               lambda node: node.close())


if __name__ == "__main__":
    sys.exit(main())
