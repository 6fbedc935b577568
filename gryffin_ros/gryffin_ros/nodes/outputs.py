"""What the planner node publishes, typed and as JSON: proposals, events and the campaign's status (also served on
~/get_status and ~/json/get_status). Nothing is published unless the node is active and not shutting down (`open_`
says so)."""

from __future__ import annotations

from collections.abc import Callable

from rclpy.lifecycle import LifecycleNode
from std_msgs.msg import String
from std_srvs.srv import Trigger

from .. import messages
from ..campaign import Campaign
from ..planner import Proposal
from . import typed
from .qos import EVENTS_QOS, LATCHED_QOS
from .recorder import BagRecorder
from .typed import GetStatus

QOS = {"proposals": LATCHED_QOS, "events": EVENTS_QOS, "status": LATCHED_QOS}


class Outputs:
    def __init__(self, node: LifecycleNode, campaign: Campaign, open_: Callable[[], bool],
                 closing: Callable[[], bool], recorder: BagRecorder | None = None):
        self._node, self._campaign, self._open, self._closing = node, campaign, open_, closing
        self._recorder = recorder  # the typed messages sent are recorded as sent (node parameter `record`)
        make = node.create_lifecycle_publisher
        self._publishers = {
            "proposals": make(typed.Proposals, "~/proposals", QOS["proposals"]),
            "events": make(typed.Event, "~/events", QOS["events"]),
            "status": make(typed.CampaignStatus, "~/status", QOS["status"]),
            "json/proposals": make(String, "~/json/proposals", LATCHED_QOS),
            "json/events": make(String, "~/json/events", EVENTS_QOS),
            "json/status": make(String, "~/json/status", LATCHED_QOS),
        }

    def destroy(self) -> None:
        for publisher in self._publishers.values():
            self._node.destroy_lifecycle_publisher(publisher)
        self._publishers = {}

    def _publish(self, name: str, msg) -> None:
        publisher = self._publishers.get(name)
        if not self._open() or publisher is None:
            return
        try:
            publisher.publish(msg)
        except Exception:  # noqa: BLE001 - shutdown or deactivation began while this callback was running
            if self._open() and not self._closing():
                raise
            return
        if self._recorder is not None and name in QOS:
            self._recorder.record(publisher.topic_name, msg, QOS[name])

    def proposals(self, proposals: list[Proposal]) -> None:
        name, n = self._campaign.name, self._campaign.n_observations
        self._publish("proposals", typed.proposals_message(name, proposals, n))
        self._publish("json/proposals", String(data=messages.proposals_message(name, proposals, n)))

    def event(self, kind: str, experiment_id: str | None = None, reason: str | None = None) -> None:
        event = {"type": kind}
        if experiment_id is not None:
            event["experiment_id"] = experiment_id
        if reason is not None:
            event["reason"] = reason
        self._publish("events", typed.event_message(event))
        self._publish("json/events", String(data=messages.dump("event", event)))

    def status(self) -> None:
        status = self._campaign.status()
        self._publish("status", typed.status_message(status))
        self._publish("json/status", String(data=messages.dump("status", status)))

    def on_get_status(self, request: GetStatus.Request, response: GetStatus.Response) -> GetStatus.Response:
        response.status = typed.status_message(self._campaign.status())
        return response

    def on_json_get_status(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        response.success, response.message = True, messages.dump("status", self._campaign.status())
        return response
