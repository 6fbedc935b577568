"""ROS 2 lifecycle node `gryffin_planner`: translates typed messages (gryffin_ros_msgs) and their JSON bridge to and
from a `Campaign` (which owns the store, the planner and the bookkeeping).

configure opens the campaign, activate starts the interfaces and proposing, deactivate stops them (a running
recommendation is stopped), cleanup closes the store. With `autostart` (the default) the node configures and
activates itself. The optimizer runs in its own callback group, so topics, ~/get_status and cancel requests stay
responsive while it works; /diagnostics reports the node in every state.
"""

from __future__ import annotations

import json
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from concurrent import futures
from pathlib import Path
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import SetParametersResult
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from std_msgs.msg import String
from std_srvs.srv import Trigger

from .. import messages
from ..campaign import Campaign
from ..planner import GryffinRosError, Proposal
from ..planner.config import read_config
from ..planner.reporting import Cancelled
from . import typed
from .qos import DIAGNOSTICS_QOS, EVENTS_QOS, LATCHED_QOS, OBSERVATIONS_SUBSCRIPTION_QOS, SERVICES_QOS
from .runner import declare, run
from .typed import GetStatus, Recommend

PARAMETERS = {
    "config": ("", "path to the campaign config (YAML or JSON; Gryffin format accepted); required; read-only"),
    "storage": ("", "SQLite file holding the campaign (default <campaign name>.sqlite); ':memory:' for none; "
                    "read-only"),
    "seed": (-1, "random seed; -1 = random (kept in the store, so a restart continues with it); read-only"),
    "autostart": (True, "configure and activate at start-up (false: wait for a lifecycle manager); read-only"),
    "batch_size": (1, "proposals per recommendation (a Recommend goal with count 0, ~/json/recommend, auto-propose)"),
    "acquisition_optimizer": ("", "'adam' (Adam + Hill) or 'genetic'; empty: as the config's general section says"),
    "auto_propose": (True, "publish the next proposals as soon as all pending experiments have reported"),
    "accept_unsolicited": (False, "accept observations whose experiment_id this planner never proposed"),
    "max_message_bytes": (messages.MAX_MESSAGE_BYTES, "larger incoming JSON messages are refused unparsed"),
    "dashboard_port": (-1, "serve the campaign's live web page on this port (0: any free port; -1: none)"),
    "dashboard_host": ("127.0.0.1", "address the web page binds to (default: this machine only)"),
}
READ_ONLY = ("config", "storage", "seed", "autostart")

REMIND_AFTER_S = 5.0
# a recommendation queued behind another one says "waiting" this often
WAIT_REPORT_S = 0.25
DIAGNOSTICS_PERIOD_S = 1.0
# rejections within this window make the diagnostics a warning
RECENT_S = 60.0
# feedback of a running recommendation at most this often (and at every change of stage)
FEEDBACK_PERIOD_S = 0.1
# overall progress of a recommendation at the start of each stage, and the stage's share
STAGES = {"waiting": (0.0, 0.0), "models": (0.0, 0.1), "optimizing": (0.1, 0.8), "selecting": (0.9, 0.1)}


class StartupError(GryffinRosError):
    """The node cannot be configured with the parameters and config it was given."""


class Deactivated(Cancelled):
    """The node left the active state, or began to shut down, while a recommendation ran."""


def check_parameter(name: str, value: Any) -> str | None:
    """Why `value` is not acceptable for parameter `name` (None when it is)."""
    if name == "config" and not value:
        return "parameter 'config' is required (path to a YAML or JSON campaign config)"
    if name == "batch_size" and value < 1:
        return f"parameter 'batch_size' must be at least 1, got {value}"
    if name == "acquisition_optimizer" and value not in ("", "adam", "genetic"):
        return f"parameter 'acquisition_optimizer' must be 'adam', 'genetic' or empty, got {value!r}"
    if name == "max_message_bytes" and value < 1024:
        return f"parameter 'max_message_bytes' must be at least 1024, got {value}"
    if name == "dashboard_port" and not -1 <= value <= 65535:
        return f"parameter 'dashboard_port' must be -1 (none), 0 (any free port) or a port up to 65535, got {value}"
    if name == "dashboard_host" and not value:
        return "parameter 'dashboard_host' must name an address (127.0.0.1: this machine only)"
    return None


class PlannerNode(LifecycleNode):
    def __init__(self) -> None:
        super().__init__("gryffin_planner")
        self.p = declare(self, PARAMETERS, READ_ONLY)
        self.campaign: Campaign | None = None
        self.storage = ""
        self.dashboard = None
        self._active = False
        self._closing = False
        self._lock = threading.Lock()  # the flags and counters below
        self._ask_blocked = False  # an ask failed; wait for new data before auto-proposing again
        self._running: set[threading.Event] = set()  # the recommendations running now (each: stop requested)
        self._idle = threading.Condition(self._lock)
        self._last_input = time.monotonic()
        self._last_ask_s: float | None = None
        self._last_error: str | None = None
        self.configure_error: str | None = None
        self._rejections: deque[tuple[float, str]] = deque(maxlen=100)
        self._guard = None  # wakes auto-propose
        # every ask runs on this one thread, whichever executor thread asked: asks on changing threads left each
        # thread's malloc arena holding its own large freed blocks (a planner node grew ~0.35 MB per experiment)
        self._planner_thread = futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="gryffin_planner_ask")
        self._action: ActionServer | None = None
        self._inputs: list = []  # (destroy, entity) of the active state: subscriptions, services, timer, guard
        self._outputs: dict[str, Any] = {}
        self.add_on_set_parameters_callback(self._on_set_parameters)
        # always there, in every state: a lifecycle manager and an operator see why a node is not running
        self.diagnostics_pub = self.create_publisher(DiagnosticArray, "/diagnostics", DIAGNOSTICS_QOS)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._publish_diagnostics, callback_group=ReentrantCallbackGroup())

    # ---- lifecycle -------------------------------------------------------------------------------------------
    def lifecycle_state(self) -> str:
        return self._state_machine.current_state[1]

    def _open_campaign(self) -> None:
        """Open the campaign (configure's work); raises StartupError (or another GryffinRosError) saying why not."""
        for name in PARAMETERS:
            reason = check_parameter(name, self.p[name])
            if reason:
                raise StartupError(reason)
        p = self.p
        # default store: <campaign name>.sqlite here (the name is validated with the rest of the config below)
        storage = p["storage"] or f"{read_config(p['config']).get('name', 'campaign')}.sqlite"
        # node parameters choose how to optimize, not what: they do not change the campaign's identity
        campaign = Campaign(p["config"], storage, seed=p["seed"] if p["seed"] >= 0 else None,
                            settings=self._settings(p["acquisition_optimizer"]),
                            accept_unsolicited=p["accept_unsolicited"])
        try:
            fraction = campaign.planner.feasible_fraction  # contradictory constraints fail here
            if p["dashboard_port"] >= 0:
                self.dashboard = self._start_dashboard(storage, p["dashboard_host"], p["dashboard_port"])
        except BaseException:
            campaign.close()
            raise
        self.campaign, self.storage = campaign, storage
        for text in campaign.warnings:
            self.get_logger().warning(text)
        # the action lives until cleanup (goals are refused while inactive): a result in flight when the node is
        # deactivated still reaches its client
        self._action = ActionServer(self, Recommend, "~/recommend", execute_callback=self._execute_recommend,
                                    goal_callback=self._on_goal, cancel_callback=lambda _goal: CancelResponse.ACCEPT,
                                    callback_group=ReentrantCallbackGroup())
        self._outputs = {
            "proposals": self.create_lifecycle_publisher(typed.Proposals, "~/proposals", LATCHED_QOS),
            "events": self.create_lifecycle_publisher(typed.Event, "~/events", EVENTS_QOS),
            "status": self.create_lifecycle_publisher(typed.CampaignStatus, "~/status", LATCHED_QOS),
            "json/proposals": self.create_lifecycle_publisher(String, "~/json/proposals", LATCHED_QOS),
            "json/events": self.create_lifecycle_publisher(String, "~/json/events", EVENTS_QOS),
            "json/status": self.create_lifecycle_publisher(String, "~/json/status", LATCHED_QOS),
        }
        self.get_logger().info(
            f"campaign '{campaign.name}' in {storage}: {campaign.n_observations} observation(s), "
            f"{len(campaign.pending)} pending; feasible fraction {fraction.value:.3g} ({fraction.method}); seed "
            f"{campaign.seed}; acquisition optimizer {campaign.config.general.acquisition_optimizer}")

    def on_configure(self, state) -> TransitionCallbackReturn:
        try:
            self._open_campaign()
        except Exception as exc:  # noqa: BLE001 - whatever it is, the node stays up, unconfigured, and says why
            reason = str(exc) if isinstance(exc, GryffinRosError) else f"internal error: {exc!r}"
            self.configure_error = reason
            self.get_logger().error(f"configure failed: {reason}")
            self._publish_diagnostics()
            return TransitionCallbackReturn.FAILURE
        self.configure_error = None
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state) -> TransitionCallbackReturn:
        result = super().on_activate(state)  # enables the lifecycle publishers
        campaign = self.campaign
        optimizer_group, observations_group = MutuallyExclusiveCallbackGroup(), MutuallyExclusiveCallbackGroup()
        status_group = ReentrantCallbackGroup()
        # observations one at a time, in arrival order (so events and the store keep that order)
        self._guard = self.create_guard_condition(self._auto_propose, callback_group=optimizer_group)
        self._inputs = [
            (self.destroy_subscription, self.create_subscription(
                typed.Observation, "~/observations", self._on_typed_observation, OBSERVATIONS_SUBSCRIPTION_QOS,
                callback_group=observations_group)),
            (self.destroy_subscription, self.create_subscription(
                String, "~/json/observations", self._on_json_observation, OBSERVATIONS_SUBSCRIPTION_QOS,
                callback_group=observations_group)),
            (self.destroy_service, self.create_service(GetStatus, "~/get_status", self._on_get_status,
                                                       qos_profile=SERVICES_QOS, callback_group=status_group)),
            (self.destroy_service, self.create_service(Trigger, "~/json/get_status", self._on_json_get_status,
                                                       qos_profile=SERVICES_QOS, callback_group=status_group)),
            (self.destroy_service, self.create_service(Trigger, "~/json/recommend", self._on_json_recommend,
                                                       qos_profile=SERVICES_QOS, callback_group=optimizer_group)),
            # experiments still owed after a quiet spell are announced again (a report may have been lost)
            (self.destroy_timer, self.create_timer(REMIND_AFTER_S / 2, self._remind, callback_group=status_group)),
            # auto-propose runs when woken (activation, an accepted observation) instead of polling with a timer
            (self.destroy_guard_condition, self._guard),
        ]
        with self._lock:
            self._active, self._ask_blocked, self._last_input = True, False, time.monotonic()
        owed = campaign.pending
        if owed:  # after a restart or a deactivation, the experiments still owed are announced to whoever takes them
            campaign.mark_unclaimed()
            self._publish_proposals(owed)
        self._publish_status()
        self._wake()
        self.get_logger().info("active")
        return result

    def on_deactivate(self, state) -> TransitionCallbackReturn:
        self._stop_inputs()
        self.get_logger().info("inactive")
        return super().on_deactivate(state)

    def _stop_inputs(self) -> None:
        """Refuse new work, stop the running recommendations (at their next checkpoint), then remove the inputs."""
        with self._lock:
            self._active = False
            for stop in self._running:
                stop.set()
            self._idle.wait_for(lambda: not self._running)
        for destroy, entity in self._inputs:
            destroy(entity)
        self._inputs, self._guard = [], None

    def on_cleanup(self, state) -> TransitionCallbackReturn:
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state) -> TransitionCallbackReturn:
        if self._active:
            self._stop_inputs()
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state) -> TransitionCallbackReturn:
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def _release(self) -> None:
        """Close the dashboard and the campaign, remove the publishers (back to unconfigured)."""
        for publisher in self._outputs.values():
            self.destroy_lifecycle_publisher(publisher)
        self._outputs = {}
        if self._action is not None:
            self._action.destroy()
            self._action = None
        if self.dashboard is not None:
            self.dashboard.close()
            self.dashboard = None
        if self.campaign is not None:
            self.campaign.close()
            self.campaign = None

    def begin_shutdown(self) -> None:
        """Stop publishing and auto-proposing (observations arriving meanwhile are still stored, until close), and
        stop the running recommendations at their next checkpoint: their goals are aborted with the reason, while
        the executor still spins to deliver it (`settled` says when they are done)."""
        with self._lock:
            self._closing = True
            for stop in self._running:
                stop.set()

    def settled(self) -> bool:
        """No recommendation is running (each stopped one has handed its goal its result)."""
        with self._lock:
            return not self._running

    def close(self) -> None:
        """Stop a running recommendation and release the campaign, after observations being stored are done."""
        self._closing = True
        if self.lifecycle_state() == "active":
            self._stop_inputs()
        self._release()
        self._planner_thread.shutdown(wait=True)

    # ---- parameters ------------------------------------------------------------------------------------------
    @staticmethod
    def _settings(optimizer: str) -> dict[str, Any] | None:
        return {"acquisition_optimizer": optimizer} if optimizer else None

    def _on_set_parameters(self, parameters) -> SetParametersResult:
        """Validate a set at run time and apply it to the open campaign; a refused set names the reason."""
        changes = {p.name: p.value for p in parameters}
        for name, value in changes.items():
            reason = check_parameter(name, value)
            if reason:
                return SetParametersResult(successful=False, reason=reason)
        campaign = self.campaign
        try:
            if campaign is not None and "acquisition_optimizer" in changes:
                campaign.use_settings(self._settings(changes["acquisition_optimizer"]) or {})
            if campaign is not None and ({"dashboard_port", "dashboard_host"} & set(changes)):
                self._restart_dashboard(changes)
        except GryffinRosError as exc:
            return SetParametersResult(successful=False, reason=str(exc))
        if campaign is not None and "accept_unsolicited" in changes:
            campaign.accept_unsolicited = changes["accept_unsolicited"]
        self.p.update(changes)
        if campaign is not None and ("auto_propose" in changes or "batch_size" in changes):
            self._wake()
        return SetParametersResult(successful=True)

    def _restart_dashboard(self, changes: dict[str, Any]) -> None:
        port = changes.get("dashboard_port", self.p["dashboard_port"])
        host = changes.get("dashboard_host", self.p["dashboard_host"])
        started = self._start_dashboard(self.storage, host, port) if port >= 0 else None
        if self.dashboard is not None:
            self.dashboard.close()
        self.dashboard = started

    def _start_dashboard(self, storage: str, host: str, port: int):
        from ..dashboard import start  # the web server and plotly load only when asked for
        if storage == ":memory:":
            raise StartupError("parameter 'dashboard_port': the dashboard reads the campaign store; give 'storage' a "
                               "file")
        try:
            server = start(storage, host, port, Path(self.p["config"]).resolve().parent)
        except GryffinRosError as exc:
            raise StartupError(f"parameter 'dashboard_port': {exc}") from None
        self.get_logger().info(f"dashboard: {server.url}")
        if not server.loopback:
            self.get_logger().warning(f"dashboard on {host}: reachable from other machines, without authentication")
        return server

    # ---- outputs ---------------------------------------------------------------------------------------------
    def _publish(self, name: str, msg) -> None:
        publisher = self._outputs.get(name)
        if self._closing or not self._active or publisher is None:  # nothing goes out unless active
            return
        try:
            publisher.publish(msg)
        except Exception:  # noqa: BLE001 - shutdown or deactivation began while this callback was running
            if not self._closing and self._active:
                raise

    def _publish_proposals(self, proposals: list[Proposal]) -> None:
        campaign = self.campaign
        self._publish("proposals", typed.proposals_message(campaign.name, proposals, campaign.n_observations))
        self._publish("json/proposals", String(data=messages.proposals_message(campaign.name, proposals,
                                                                              campaign.n_observations)))

    def _event(self, kind: str, experiment_id: str | None = None, reason: str | None = None) -> None:
        event = {"type": kind}
        if experiment_id is not None:
            event["experiment_id"] = experiment_id
        if reason is not None:
            event["reason"] = reason
        if kind == "observation_rejected":
            with self._lock:
                self._rejections.append((time.monotonic(), reason or ""))
        self._publish("events", typed.event_message(event))
        self._publish("json/events", String(data=messages.dump("event", event)))

    def _publish_status(self) -> None:
        if self.campaign is None:
            return
        status = self.campaign.status()
        self._publish("status", typed.status_message(status))
        self._publish("json/status", String(data=messages.dump("status", status)))

    def _publish_diagnostics(self) -> None:
        if self._closing:
            return
        array = DiagnosticArray()
        array.header.stamp = self.get_clock().now().to_msg()
        array.status = [self.diagnostic_status()]
        try:
            self.diagnostics_pub.publish(array)
        except Exception:  # noqa: BLE001 - the context is going away
            if not self._closing:
                raise

    def diagnostic_status(self) -> DiagnosticStatus:
        """The node's health: level from the lifecycle state, the campaign's state and recent errors."""
        state = self.lifecycle_state()
        values: dict[str, Any] = {"lifecycle_state": state}
        with self._lock:
            now = time.monotonic()
            recent = [reason for t, reason in self._rejections if now - t < RECENT_S]
            last_ask, last_error = self._last_ask_s, self._last_error
        campaign = self.campaign
        if campaign is None:
            level = DiagnosticStatus.ERROR if self.configure_error else DiagnosticStatus.WARN
            message = f"configure failed: {self.configure_error}" if self.configure_error else state
            name = "gryffin_planner"
        else:
            status = campaign.status()
            best = status["best"]
            values.update(campaign=status["campaign"], storage=self.storage, state=status["state"],
                          observations=status["n_observations"], pending=status["n_pending"],
                          failed=status["n_failed"], rejected_last_minute=len(recent),
                          best="none" if best is None else json.dumps(best["objectives"]),
                          best_experiment_id="" if best is None else best["experiment_id"] or "",
                          last_ask_s="none" if last_ask is None else f"{last_ask:.3f}")
            name = f"gryffin_planner: {status['campaign']}"
            if state != "active":
                level, message = DiagnosticStatus.WARN, state
            elif status["state"] == "error":
                level, message = DiagnosticStatus.ERROR, f"the last recommendation failed: {last_error}"
            elif recent:
                level, message = DiagnosticStatus.WARN, (f"{len(recent)} observation(s) rejected in the last "
                                                         f"{RECENT_S:.0f} s; last: {recent[-1]}")
            elif status["warnings"]:
                level, message = DiagnosticStatus.WARN, "; ".join(status["warnings"])
            else:
                level, message = DiagnosticStatus.OK, status["state"]
        if last_error:
            values["last_error"] = last_error
        return DiagnosticStatus(level=level, name=name, message=message, hardware_id=self.get_fully_qualified_name(),
                                values=[KeyValue(key=k, value=str(v)) for k, v in values.items()])

    # ---- inputs ----------------------------------------------------------------------------------------------
    def _on_typed_observation(self, msg: typed.Observation) -> None:
        raw = typed.observation_record(msg)
        try:
            item = typed.observation_item(msg)
        except GryffinRosError as exc:
            self._refuse(str(exc), raw, msg.experiment_id or None)
            return
        self._take([item], lambda _item: raw)

    def _on_json_observation(self, msg: String) -> None:
        try:
            items = messages.observation_items(
                messages.parse("observation", msg.data, self.p["max_message_bytes"]))
        except GryffinRosError as exc:  # the id, when the refused message names one (schema errors)
            self._refuse(str(exc), msg.data, getattr(exc, "experiment_id", None))
            return
        except Exception as exc:  # whatever a sender manages to trigger, the node stays up and says so
            self.get_logger().error(f"internal error parsing an observation message: {exc!r}")
            self._event("observation_rejected", reason=f"internal error: {exc!r}")
            return
        # the store keeps the message as it arrived; of a batch, each observation's own part
        self._take(items, lambda item: msg.data if len(items) == 1 else json.dumps(item))

    def _refuse(self, reason: str, raw: str, experiment_id: str | None = None) -> None:
        self._event("observation_rejected", experiment_id, reason)
        self.campaign.reject(reason, raw, experiment_id)

    def _take(self, items: list[dict], raw: Callable[[dict], str]) -> None:
        for item in items:
            try:
                self.campaign.observe(item, raw=raw(item))
            except GryffinRosError as exc:
                self._event("observation_rejected", item.get("experiment_id"), str(exc))
                continue
            except Exception as exc:  # a bug must not take the node down with the lab's data
                self.get_logger().error(f"internal error on observation {item.get('experiment_id')}: {exc!r}")
                self._event("observation_rejected", item.get("experiment_id"), f"internal error: {exc!r}")
                continue
            with self._lock:
                self._last_input = time.monotonic()
                self._ask_blocked = False
            self._event("observation_accepted", item["experiment_id"])
            self._wake()
        self._publish_status()

    def _wake(self) -> None:
        guard = self._guard
        if guard is not None:
            guard.trigger()

    def _remind(self) -> None:
        with self._lock:
            quiet = time.monotonic() - self._last_input > REMIND_AFTER_S
            if quiet:
                self._last_input = time.monotonic()
        owed = self.campaign.pending if quiet and self.p["auto_propose"] else []
        if owed:
            self._publish_proposals(owed)

    def _on_get_status(self, request: GetStatus.Request, response: GetStatus.Response) -> GetStatus.Response:
        response.status = typed.status_message(self.campaign.status())
        return response

    def _on_json_get_status(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        response.success, response.message = True, messages.dump("status", self.campaign.status())
        return response

    # ---- optimizer -------------------------------------------------------------------------------------------
    def _recommend(self, make: Callable[[Callable[[str, float, int], None]], list[Proposal]],
                   feedback: Callable[[str, float, int], None] | None = None,
                   cancelled: Callable[[], bool] = lambda: False) -> list[Proposal]:
        """Run `make(progress)` (which proposes, calling progress at checkpoints), reporting status and errors; it
        stops at the next checkpoint once `cancelled()` or a deactivation says so (Cancelled). A failure is raised
        as GryffinRosError."""
        stop = threading.Event()
        with self._lock:
            if self._closing:
                raise Deactivated(self._stopped_reason())
            if not self._active:
                raise GryffinRosError(f"the planner is not active (lifecycle state {self.lifecycle_state()})")
            self._running.add(stop)
        started = time.monotonic()
        reported = [False]

        def progress(stage: str, fraction: float, ready: int) -> None:
            if stop.is_set():
                raise Deactivated(self._stopped_reason())
            if cancelled():
                raise Cancelled("canceled by the client; nothing was proposed")
            if not reported[0] and stage != "waiting":
                reported[0] = True
                self._publish_status()  # "optimizing"
            if feedback is not None:
                feedback(stage, fraction, ready)

        try:
            proposals = self._await(self._planner_thread.submit(make, progress), stop, feedback, cancelled)
        except Cancelled:
            self._publish_status()
            raise
        except Exception as exc:
            with self._lock:
                self._ask_blocked = True
            if not isinstance(exc, GryffinRosError):  # a bug: report it, keep the node and the data alive
                self.get_logger().error(f"internal error while proposing: {exc!r}")
                exc = GryffinRosError(f"internal error: {exc!r}")
            with self._lock:
                self._last_error = str(exc)
            self._event("error", reason=str(exc))
            self._publish_status()
            raise exc
        finally:
            with self._lock:
                self._running.discard(stop)
                self._idle.notify_all()
        with self._lock:
            self._last_ask_s = time.monotonic() - started
        self._event("proposals_ready", reason=f"{len(proposals)} proposal(s) after "
                                              f"{self.campaign.n_observations} observation(s)")
        self._publish_status()
        return proposals

    def _stopped_reason(self) -> str:
        if self._closing:
            return "the planner is shutting down; nothing was proposed (ask again when it is back)"
        return "the planner was deactivated while recommending; nothing was proposed"

    def _await(self, future: futures.Future, stop: threading.Event,
               feedback: Callable[[str, float, int], None] | None, cancelled: Callable[[], bool]) -> list[Proposal]:
        """The result of an ask queued on the planner thread; while it waits behind another one it reports
        "waiting" and can be stopped before it starts."""
        while True:
            try:
                return future.result(timeout=WAIT_REPORT_S)
            except futures.TimeoutError:
                if future.running():
                    continue
                if stop.is_set() and future.cancel():
                    raise Deactivated(self._stopped_reason()) from None
                if cancelled() and future.cancel():
                    raise Cancelled("canceled by the client; nothing was proposed") from None
                if feedback is not None:
                    feedback("waiting", 0.0, 0)

    def _auto_propose(self) -> None:
        with self._lock:
            due = self.p["auto_propose"] and not self._ask_blocked and not self._closing and self._active
        if not due or self.campaign.pending:
            return
        try:
            proposals = self._recommend(lambda progress: self.campaign.propose(self.p["batch_size"], False,
                                                                                 progress=progress))
        except GryffinRosError:
            return
        self._publish_proposals(proposals)

    def _on_json_recommend(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        try:
            proposals = self._recommend(lambda progress: self.campaign.claim(self.p["batch_size"], progress=progress))
        except GryffinRosError as exc:
            response.success = False
            response.message = messages.dump("error", {"error": type(exc).__name__, "reason": str(exc)})
            return response
        response.success = True
        response.message = messages.proposals_message(self.campaign.name, proposals, self.campaign.n_observations)
        return response

    def _on_goal(self, goal: Recommend.Goal) -> GoalResponse:
        return GoalResponse.ACCEPT if self._active and not self._closing else GoalResponse.REJECT

    def _execute_recommend(self, goal_handle) -> Recommend.Result:
        count = goal_handle.request.count or self.p["batch_size"]
        instrument = goal_handle.request.instrument
        started, last = time.monotonic(), [None, 0.0]

        def feedback(stage: str, fraction: float, ready: int) -> None:
            now = time.monotonic()
            if stage == last[0] and now - last[1] < FEEDBACK_PERIOD_S:
                return
            last[0], last[1] = stage, now
            base, share = STAGES.get(stage, (0.0, 0.0))
            goal_handle.publish_feedback(Recommend.Feedback(stage=stage, progress=base + share * fraction,
                                                            proposals_ready=ready, elapsed_s=now - started))

        result = Recommend.Result()
        try:
            proposals = self._recommend(lambda progress: self.campaign.claim(count, progress, instrument), feedback,
                                        lambda: goal_handle.is_cancel_requested)
        except Cancelled as exc:
            result.error = str(exc)
            result.n_observations = self.campaign.n_observations
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
            else:
                goal_handle.abort()
            return result
        except GryffinRosError as exc:
            result.error = str(exc)
            goal_handle.abort()
            return result
        result.proposals = [typed.proposal_message(p) for p in proposals]
        result.n_observations = self.campaign.n_observations
        goal_handle.succeed()
        return result


def start(node: PlannerNode) -> None:
    """autostart: configure and activate now; a failed configure stops the process with the reason (exit code 2)."""
    if not node.p["autostart"]:
        node.get_logger().info("autostart is off: unconfigured, waiting for a lifecycle manager")
        return
    if node.trigger_configure() != TransitionCallbackReturn.SUCCESS:
        raise StartupError(node.configure_error)
    node.trigger_activate()


def main(args: list[str] | None = None) -> int:
    def make() -> PlannerNode:
        node = PlannerNode()
        try:
            start(node)
        except BaseException:
            node.close()
            node.destroy_node()
            raise
        return node
    return run(make, "gryffin_planner", args, lambda: MultiThreadedExecutor(num_threads=4),
               lambda node: node.close())


if __name__ == "__main__":
    sys.exit(main())
