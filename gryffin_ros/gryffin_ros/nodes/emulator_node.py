"""ROS 2 emulator nodes that close the loop in simulation: `flow_reactor_emulator` (the C60 flow reactor BNN) and
`redox_emulator` (DFT lookup of benzothiadiazole candidates). Each runs experiments through its emulator and
publishes one typed observation per experiment, optionally after a simulated experiment time and with injected
failures (failed = true); every output goes into `meta_json`. Names are relative (`<planner>/proposals`), so
`-r __ns:=/lab2` moves an emulator and its planner together.

Which experiments: by default every new proposal announced on `<planner>/proposals` (one instrument per planner).
With `claim` on, the node is one instrument among several: it asks the planner's `recommend` action for
`claim_count` experiments under its own full name whenever it is idle, so instruments share the batches and no
experiment runs twice; an ask that hears nothing for `response_timeout_s` is sent again, and the planner answers a
repeated ask with the experiments already claimed (a lost answer loses nothing).

Either way a result is kept until the planner acknowledges it on `<planner>/events` (accepted, or rejected as
already reported) and sent again every `resend_s` until then, so a result measured while the network is down
reaches the planner when it returns."""

from __future__ import annotations

import sys
import time
from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np
from rclpy.action import ActionClient
from rclpy.node import Node

from ..emulators import FlowReactorEmulator, RedoxEmulator
from ..planner import GryffinRosError
from . import typed
from .qos import EVENTS_QOS, LATCHED_QOS, OBSERVATIONS_QOS
from .runner import declare, run

COMMON = {
    "experiment_time_s": (0.0, "simulated duration of one experiment, in seconds"),
    "failure_rate": (0.0, "probability that an experiment fails (reported with objectives null)"),
    "seed": (-1, "random seed of the emulator; -1 = random"),
    "planner": ("gryffin_planner", "the planner node whose proposals this emulator runs (a name relative to this "
                                   "node's namespace, or absolute)"),
    "claim": (False, "take experiments with the planner's recommend action under this node's name (several "
                     "instruments share the batches) instead of running every proposal announced"),
    "claim_count": (1, "experiments asked for at a time with claim on"),
    "response_timeout_s": (10.0, "with claim on, an ask that hears nothing from the planner for this long is sent "
                                 "again"),
    "resend_s": (2.0, "a result not yet acknowledged by the planner is sent again after this long"),
}
# how often an idle claiming instrument looks for the planner's action server
LOOK_FOR_PLANNER_S = 0.2
KINDS: dict[str, dict[str, Any]] = {
    "flow_reactor_emulator": {
        "parameters": {
            "parameters": (["F_C", "F_S", "T"], "names of the C60 flow, sultine flow and temperature parameters"),
            "objectives": (["X1_X2", "cost"], "outputs reported as objectives, any of X0 X1 X2 X3 X1_X2 cost"),
        },
        "make": lambda p, seed: FlowReactorEmulator(seed=seed, parameters=tuple(p["parameters"])),
    },
    "redox_emulator": {
        "parameters": {
            "objectives": (["abs_lam_diff", "ered", "gsol"], "outputs reported as objectives"),
            "noise": (False, "add the published per-candidate Gaussian noise to the DFT values"),
        },
        "make": lambda p, seed: RedoxEmulator(noise=p["noise"], seed=seed),
    },
}


class EmulatorNode(Node):
    def __init__(self, kind: str) -> None:
        super().__init__(kind)
        p = declare(self, {**COMMON, **KINDS[kind]["parameters"]})
        if not 0.0 <= p["failure_rate"] <= 1.0:
            raise GryffinRosError(f"parameter 'failure_rate' must be in [0, 1], got {p['failure_rate']}")
        if p["experiment_time_s"] < 0:
            raise GryffinRosError(f"parameter 'experiment_time_s' must be >= 0, got {p['experiment_time_s']}")
        for name in ("response_timeout_s", "resend_s"):
            if not p[name] > 0:
                raise GryffinRosError(f"parameter '{name}' must be > 0, got {p[name]}")
        if p["claim_count"] < 1:
            raise GryffinRosError(f"parameter 'claim_count' must be >= 1, got {p['claim_count']}")
        if "parameters" in p and len(p["parameters"]) != 3:
            raise GryffinRosError("parameter 'parameters' must name three parameters: C60 flow, sultine flow, T")
        seed = None if p["seed"] < 0 else p["seed"]
        self.emulator = KINDS[kind]["make"](p, seed)
        unknown = set(p["objectives"]) - set(self.emulator.outputs)
        if unknown or not p["objectives"]:
            raise GryffinRosError(f"parameter 'objectives' must list outputs among {list(self.emulator.outputs)}, "
                                  f"got {list(p['objectives'])}")
        self.experiment_time, self.failure_rate = p["experiment_time_s"], p["failure_rate"]
        self.objectives = list(p["objectives"])
        self.rng = np.random.default_rng(None if seed is None else seed + 1)
        self.queue: deque[dict] = deque()
        self.seen: set[str] = set()
        self.reported: dict[str, typed.Observation] = {}  # experiment_id -> the observation message sent
        self.unacknowledged: dict[str, float] = {}  # experiment_id -> when its report was last sent
        self.running: tuple[dict, float] | None = None
        self.claiming, self.claim_count = p["claim"], p["claim_count"]
        self.response_timeout, self.resend = p["response_timeout_s"], p["resend_s"]
        self.asking: object | None = None  # the ask in flight (a token; answers to older asks are still taken)
        self.heard = self.looked = 0.0  # last word from the planner about the ask in flight; last server check
        planner = p["planner"].rstrip("/")
        if not planner:
            raise GryffinRosError("parameter 'planner' must name the planner node (default gryffin_planner)")
        self.publisher = self.create_publisher(typed.Observation, f"{planner}/observations", OBSERVATIONS_QOS)
        self.create_subscription(typed.Proposals, f"{planner}/proposals", self._on_proposals, LATCHED_QOS)
        self.create_subscription(typed.Event, f"{planner}/events", self._on_event, EVENTS_QOS)
        self.recommend = ActionClient(self, typed.Recommend, f"{planner}/recommend") if self.claiming else None
        self.create_timer(0.005, self._work)

    def _on_proposals(self, msg: typed.Proposals) -> None:
        for proposal in msg.proposals:
            experiment_id = proposal.experiment_id
            if experiment_id in self.reported:
                # announced again (the planner restarted): the report may have been lost, so send it again; a
                # planner that has it already rejects the copy as a duplicate
                self.publisher.publish(self.reported[experiment_id])
                continue
            if not self.claiming:  # a claiming instrument runs only what it was handed
                self._take(proposal)

    def _take(self, proposal: typed.ProposalMsg) -> None:
        experiment_id = proposal.experiment_id
        if experiment_id in self.seen:
            return
        try:
            params = typed.params_of(proposal.params)
        except GryffinRosError as exc:
            self.get_logger().warning(f"proposal {experiment_id}: {exc}; skipped")
            return
        missing = [n for n in self.emulator.parameters if n not in params]
        if missing:
            self.get_logger().warning(f"proposal {experiment_id} lacks {missing}; skipped")
            return
        self.seen.add(experiment_id)
        self.queue.append({"experiment_id": experiment_id, "params": params})

    def _on_event(self, msg: typed.Event) -> None:
        if msg.experiment_id not in self.unacknowledged:
            return
        if msg.type == typed.Event.OBSERVATION_ACCEPTED:
            del self.unacknowledged[msg.experiment_id]
        elif msg.type == typed.Event.OBSERVATION_REJECTED:
            del self.unacknowledged[msg.experiment_id]  # stored already, or refused for good: sending again is moot
            if "already reported" not in msg.reason:
                self.get_logger().warning(f"the planner refused the result of {msg.experiment_id}: {msg.reason}")

    # ---- claiming experiments --------------------------------------------------------------------------------
    def _ask(self, now: float) -> None:
        if now - self.looked < LOOK_FOR_PLANNER_S:
            return
        self.looked = now
        if not self.recommend.server_is_ready():
            return
        token = self.asking = object()
        self.heard = now
        goal = typed.Recommend.Goal(count=self.claim_count, instrument=self.get_fully_qualified_name())
        sent = self.recommend.send_goal_async(goal, feedback_callback=lambda _: self._hear(token))
        sent.add_done_callback(lambda future: self._on_goal_response(token, future))

    def _hear(self, token: object) -> None:
        if token is self.asking:
            self.heard = time.monotonic()

    def _on_goal_response(self, token: object, future) -> None:
        handle = future.result()
        if not handle.accepted:  # the planner is not active: ask again a little later
            if token is self.asking:
                self.asking, self.looked = None, time.monotonic() + 1.0
            return
        self._hear(token)
        handle.get_result_async().add_done_callback(lambda done: self._on_result(token, done))

    def _on_result(self, token: object, future) -> None:
        result = future.result().result
        for proposal in result.proposals:  # an answer to an abandoned ask still counts: it was claimed for us
            self._take(proposal)
        if result.error:
            self.get_logger().warning(f"the planner proposed nothing: {result.error}")
        if token is self.asking:
            self.asking = None

    # ---- running experiments -------------------------------------------------------------------------------
    def _work(self) -> None:
        now = time.monotonic()
        for experiment_id, sent in list(self.unacknowledged.items()):
            if now - sent >= self.resend:
                self.unacknowledged[experiment_id] = now
                self.publisher.publish(self.reported[experiment_id])
        if self.claiming:
            if self.asking is not None and now - self.heard > self.response_timeout:
                self.get_logger().info(f"no answer from the planner for {self.response_timeout:g} s: asking again")
                self.asking = None
            if self.asking is None and self.running is None and not self.queue and not self.unacknowledged:
                self._ask(now)
        if self.running is None:
            if not self.queue:
                return
            self.running = (self.queue.popleft(), now)
        proposal, started = self.running
        if time.monotonic() - started < self.experiment_time:
            return
        self.running = None
        self.get_logger().info(f"measuring {proposal['experiment_id']}")
        try:
            result = self.emulator.measure(proposal["params"])
        except (KeyError, TypeError, ValueError) as exc:
            self.get_logger().warning(f"cannot emulate {proposal['experiment_id']}: {exc!r}; reported as failed")
            result = None
        failed = result is None or self.rng.random() < self.failure_rate
        meta = {**(result or {}), "instrument": self.get_fully_qualified_name()}
        observation = typed.observation_message(proposal["experiment_id"], proposal["params"],
                                                None if failed else {k: result[k] for k in self.objectives}, meta)
        self.reported[proposal["experiment_id"]] = observation
        self.unacknowledged[proposal["experiment_id"]] = time.monotonic()
        self.publisher.publish(observation)


def _main(kind: str) -> Callable[[list[str] | None], int]:
    def main(args: list[str] | None = None) -> int:
        return run(lambda: EmulatorNode(kind), kind, args)
    return main


flow_reactor_main = _main("flow_reactor_emulator")
redox_main = _main("redox_emulator")

if __name__ == "__main__":
    sys.exit({"flow_reactor": flow_reactor_main, "redox": redox_main}[sys.argv.pop(1)](None))
