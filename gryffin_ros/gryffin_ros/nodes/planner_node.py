"""ROS 2 lifecycle node `gryffin_planner`: translates typed messages (gryffin_ros_msgs) and their JSON bridge to and
from a `Campaign`, which owns the store, the planner, the bookkeeping and the policy (ask queue, auto-propose,
reminders). Parameters: `parameters`; health: `diagnostics`; asks and the Recommend action: `recommend`; publishers
and status services: `outputs`; incoming observations: `observations`; the web page: `web`.

configure opens the campaign, activate starts the interfaces and serving, deactivate stops them (a running ask is
stopped), cleanup closes the store; `autostart` (the default) configures and activates at once. /diagnostics
reports the node in every state.
"""

from __future__ import annotations

import sys

from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import SetParametersResult
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from std_msgs.msg import String
from std_srvs.srv import Trigger

from ..campaign import REMIND_AFTER_S, Campaign
from ..planner import GryffinRosError
from ..planner.config import read_config
from . import diagnostics, typed
from .observations import ObservationInput
from .outputs import Outputs
from .parameters import PARAMETERS, READ_ONLY, check_parameter, settings
from .qos import DIAGNOSTICS_QOS, OBSERVATIONS_SUBSCRIPTION_QOS, SERVICES_QOS
from .recommend import Asks
from .recorder import BagRecorder, campaign_recorder
from .runner import declare, run
from .typed import GetStatus, Recommend
from .web import start_dashboard

DIAGNOSTICS_PERIOD_S = 1.0
DEACTIVATED = "the planner was deactivated while recommending; nothing was proposed"
SHUTTING_DOWN = "the planner is shutting down; nothing was proposed (ask again when it is back)"


class StartupError(GryffinRosError):
    """The node cannot be configured with the parameters and config it was given."""


class PlannerNode(LifecycleNode):
    def __init__(self) -> None:
        super().__init__("gryffin_planner")
        self.p = declare(self, PARAMETERS, READ_ONLY)
        self.campaign: Campaign | None = None
        self.storage = ""
        self.dashboard = None
        self._active = False
        self._closing = False
        self.configure_error: str | None = None
        self._guard = None  # wakes auto-propose
        self._action: ActionServer | None = None
        self._inputs: list = []  # (destroy, entity) of the active state: subscriptions, services, timer, guard
        self.outputs: Outputs | None = None
        self.observations: ObservationInput | None = None
        self.recorder: BagRecorder | None = None
        self.asks: Asks | None = None
        self.add_on_set_parameters_callback(self._on_set_parameters)
        # always there, in every state: a lifecycle manager and an operator see why a node is not running
        self.diagnostics_pub = self.create_publisher(DiagnosticArray, "/diagnostics", DIAGNOSTICS_QOS)
        self.create_timer(DIAGNOSTICS_PERIOD_S, lambda: diagnostics.publish(self),
                          callback_group=ReentrantCallbackGroup())

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
        campaign = Campaign(p["config"], storage, seed=p["seed"] if p["seed"] >= 0 else None,
                            settings=settings(p["acquisition_optimizer"]), accept_unsolicited=p["accept_unsolicited"])
        try:
            fraction = campaign.planner.feasible_fraction  # contradictory constraints fail here
            if p["dashboard_port"] >= 0:
                self.dashboard = start_dashboard(storage, p["dashboard_host"], p["dashboard_port"], p["config"],
                                                 self.get_logger())
            # every typed message sent or received, into a bag (docs/ros.md, "Recording a campaign")
            if p["record"]:
                self.recorder = campaign_recorder(p["record"], p["config"], campaign.store.get_meta("config") or "",
                                                  campaign.seed)
        except BaseException:
            if self.dashboard is not None:
                self.dashboard.close()
                self.dashboard = None
            campaign.close()
            raise
        self.campaign, self.storage = campaign, storage
        for text in campaign.warnings:
            self.get_logger().warning(text)
        # the action lives until cleanup (goals are refused while inactive): a result in flight when the node is
        # deactivated still reaches its client
        self.outputs = Outputs(self, campaign, lambda: self._active and not self._closing, lambda: self._closing,
                               self.recorder)
        self.observations = ObservationInput(campaign, self.outputs, self._wake, lambda: self.p["max_message_bytes"],
                                             self.get_logger(), self.recorder, self.resolve_topic_name)
        self.asks = Asks(campaign, self.outputs, lambda: self.p["batch_size"])
        self._action = ActionServer(self, Recommend, "~/recommend", execute_callback=self.asks.execute_recommend,
                                    goal_callback=self._on_goal, cancel_callback=lambda _goal: CancelResponse.ACCEPT,
                                    callback_group=ReentrantCallbackGroup())
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
            diagnostics.publish(self)
            return TransitionCallbackReturn.FAILURE
        self.configure_error = None
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state) -> TransitionCallbackReturn:
        result = super().on_activate(state)  # enables the lifecycle publishers
        optimizer_group, observations_group = MutuallyExclusiveCallbackGroup(), MutuallyExclusiveCallbackGroup()
        status_group = ReentrantCallbackGroup()
        # observations one at a time, in arrival order (so events and the store keep that order)
        self._guard = self.create_guard_condition(self._auto_propose, callback_group=optimizer_group)
        self._inputs = [
            (self.destroy_subscription, self.create_subscription(
                typed.Observation, "~/observations", self.observations.on_typed, OBSERVATIONS_SUBSCRIPTION_QOS,
                callback_group=observations_group)),
            (self.destroy_subscription, self.create_subscription(
                String, "~/json/observations", self.observations.on_json, OBSERVATIONS_SUBSCRIPTION_QOS,
                callback_group=observations_group)),
            (self.destroy_service, self.create_service(GetStatus, "~/get_status", self.outputs.on_get_status,
                                                       qos_profile=SERVICES_QOS, callback_group=status_group)),
            (self.destroy_service, self.create_service(Trigger, "~/json/get_status", self.outputs.on_json_get_status,
                                                       qos_profile=SERVICES_QOS, callback_group=status_group)),
            (self.destroy_service, self.create_service(Trigger, "~/json/recommend", self.asks.on_json_recommend,
                                                       qos_profile=SERVICES_QOS, callback_group=optimizer_group)),
            (self.destroy_timer, self.create_timer(REMIND_AFTER_S / 2, self._remind, callback_group=status_group)),
            # auto-propose runs when woken (activation, an accepted observation) instead of polling with a timer
            (self.destroy_guard_condition, self._guard),
        ]
        owed = self.campaign.serve()
        self._active = True
        if owed:  # after a restart or a deactivation, the experiments still owed are announced to whoever takes them
            self.outputs.proposals(owed)
        self.outputs.status()
        self._wake()
        self.get_logger().info("active")
        return result

    def on_deactivate(self, state) -> TransitionCallbackReturn:
        self._stop_inputs()
        self.get_logger().info("inactive")
        return super().on_deactivate(state)

    def _stop_inputs(self) -> None:
        """Refuse new work, stop the running recommendations (at their next checkpoint), then remove the inputs."""
        self._active = False
        if self.campaign is not None:
            self._stop_asks(SHUTTING_DOWN if self._closing else DEACTIVATED, wait=True)
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

    on_error = on_cleanup  # back to unconfigured, released

    def _release(self) -> None:
        """Close the dashboard and the campaign, remove the publishers (back to unconfigured)."""
        if self.outputs is not None:
            self.outputs.destroy()
            self.outputs = self.observations = self.asks = None
        if self._action is not None:
            self._action.destroy()
            self._action = None
        if self.dashboard is not None:
            self.dashboard.close()
            self.dashboard = None
        if self.campaign is not None:
            self.campaign.close()
            self.campaign = None
        if self.recorder is not None:
            self.recorder.close()
            self.recorder = None

    def begin_shutdown(self) -> None:
        """Stop publishing and auto-proposing (observations arriving meanwhile are still stored, until close), and
        stop the running recommendations at their next checkpoint: their goals are aborted with the reason, while
        the executor still spins to deliver it (`settled` says when they are done)."""
        self._closing = True
        if self.campaign is not None:
            self._stop_asks(SHUTTING_DOWN, wait=False)

    def _stop_asks(self, reason: str, wait: bool) -> None:
        """Stop serving asks; the running ones stop at their next checkpoint (said in the log: an operator sees why
        a deactivation or a stop waits)."""
        running = self.campaign.asks.in_progress()
        if running:
            self.get_logger().info(f"stopping {running} recommendation(s) in progress: {reason}")
        self.campaign.stop_serving(reason, wait=wait)

    def settled(self) -> bool:
        """No recommendation is running (each stopped one has handed its goal its result)."""
        campaign = self.campaign
        return campaign is None or campaign.asks.settled()

    def close(self) -> None:
        """Stop a running recommendation and release the campaign, after observations being stored are done."""
        self._closing = True
        if self.lifecycle_state() == "active":
            self._stop_inputs()
        self._release()

    # ---- parameters ------------------------------------------------------------------------------------------
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
                campaign.use_settings(settings(changes["acquisition_optimizer"]) or {})
            if campaign is not None and ({"dashboard_port", "dashboard_host"} & set(changes)):
                port = changes.get("dashboard_port", self.p["dashboard_port"])
                host = changes.get("dashboard_host", self.p["dashboard_host"])
                started = (start_dashboard(self.storage, host, port, self.p["config"], self.get_logger())
                           if port >= 0 else None)
                if self.dashboard is not None:
                    self.dashboard.close()
                self.dashboard = started
        except GryffinRosError as exc:
            return SetParametersResult(successful=False, reason=str(exc))
        if campaign is not None and "accept_unsolicited" in changes:
            campaign.accept_unsolicited = changes["accept_unsolicited"]
        self.p.update(changes)
        if campaign is not None and ("auto_propose" in changes or "batch_size" in changes):
            self._wake()
        return SetParametersResult(successful=True)

    # ---- inputs ----------------------------------------------------------------------------------------------
    def _wake(self) -> None:
        guard = self._guard
        if guard is not None:
            guard.trigger()

    def _remind(self) -> None:
        owed = self.campaign.owed_after_quiet() if self.p["auto_propose"] else []
        if owed:
            self.outputs.proposals(owed)

    def _on_goal(self, goal: Recommend.Goal) -> GoalResponse:
        return GoalResponse.ACCEPT if self._active and not self._closing else GoalResponse.REJECT

    def _auto_propose(self) -> None:
        if self.p["auto_propose"] and self._active and not self._closing:
            self.asks.auto_propose()


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
