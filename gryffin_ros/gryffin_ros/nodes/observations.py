"""Observations arriving at the planner node, typed or as JSON, handed to the campaign one by one: each accepted
one is announced (`observation_accepted`) and wakes auto-propose; each refused one is announced with the reason
and recorded in the campaign's store, with its experiment_id whenever the message names one. With a `record`
callback, each message is handed to it as received, before it is judged (the bag shows accept or reject in the
events that follow it)."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

from std_msgs.msg import String

from .. import messages
from ..campaign import Campaign
from ..planner import GryffinRosError
from . import typed
from .outputs import Outputs
from .qos import OBSERVATIONS_SUBSCRIPTION_QOS
from .recorder import BagRecorder


class ObservationInput:
    def __init__(self, campaign: Campaign, outputs: Outputs, accepted: Callable[[], None],
                 max_message_bytes: Callable[[], int], logger: Any, recorder: BagRecorder | None = None,
                 resolve: Callable[[str], str] = str):
        self._campaign, self._outputs, self._accepted = campaign, outputs, accepted
        self._max_bytes, self._logger = max_message_bytes, logger
        self._recorder = recorder  # each message as received, under its topic's name on the wire (`resolve`)
        self._topics = {"typed": resolve("~/observations"), "json": resolve("~/json/observations")}

    def _record(self, kind: str, msg: Any) -> None:
        if self._recorder is not None:
            self._recorder.record(self._topics[kind], msg, OBSERVATIONS_SUBSCRIPTION_QOS)

    def on_typed(self, msg: typed.Observation) -> None:
        self._record("typed", msg)
        raw = typed.observation_record(msg)
        try:
            item = typed.observation_item(msg)
        except GryffinRosError as exc:
            self._refuse(str(exc), raw, msg.experiment_id or None)
            return
        self._take([item], lambda _item: raw)

    def on_json(self, msg: String) -> None:
        self._record("json", msg)
        try:
            items = messages.observation_items(messages.parse("observation", msg.data, self._max_bytes()))
        except GryffinRosError as exc:  # the id, when the refused message names one (schema errors)
            self._refuse(str(exc), msg.data, getattr(exc, "experiment_id", None))
            return
        except Exception as exc:  # whatever a sender manages to trigger, the node stays up and says so
            self._logger.error(f"internal error parsing an observation message: {exc!r}")
            self._refuse(f"internal error: {exc!r}", msg.data)
            return
        # the store keeps the message as it arrived; of a batch, each observation's own part
        self._take(items, lambda item: msg.data if len(items) == 1 else json.dumps(item))

    def _refuse(self, reason: str, raw: str, experiment_id: str | None = None) -> None:
        self._outputs.event("observation_rejected", experiment_id, reason)
        self._campaign.reject(reason, raw, experiment_id)

    def _take(self, items: list[dict], raw: Callable[[dict], str]) -> None:
        for item in items:
            try:
                self._campaign.observe(item, raw=raw(item))  # a refusal is recorded in the store by the campaign
            except GryffinRosError as exc:
                self._outputs.event("observation_rejected", item.get("experiment_id"), str(exc))
                continue
            except Exception as exc:  # a bug must not take the node down with the lab's data
                self._logger.error(f"internal error on observation {item.get('experiment_id')}: {exc!r}")
                self._refuse(f"internal error: {exc!r}", raw(item), item.get("experiment_id"))
                continue
            self._outputs.event("observation_accepted", item["experiment_id"])
            self._accepted()
        self._outputs.status()
