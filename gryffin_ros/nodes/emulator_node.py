"""ROS 2 emulator nodes that close the loop in simulation: `flow_reactor_emulator` (the C60 flow reactor BNN) and
`redox_emulator` (DFT lookup of benzothiadiazole candidates). Each runs every new proposed experiment through its
emulator and publishes one typed observation per experiment, optionally after a simulated experiment time and with
injected failures (failed = true); every output goes into `meta_json`. Names are relative (`<planner>/proposals`),
so `-r __ns:=/lab2` moves an emulator and its planner together."""

from __future__ import annotations

import sys
import time
from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np
from rclpy.node import Node

from ..emulators import FlowReactorEmulator, RedoxEmulator
from ..planner import GryffinRosError
from . import typed
from .qos import LATCHED_QOS, OBSERVATIONS_QOS
from .runner import declare, run

COMMON = {
    "experiment_time_s": (0.0, "simulated duration of one experiment, in seconds"),
    "failure_rate": (0.0, "probability that an experiment fails (reported with objectives null)"),
    "seed": (-1, "random seed of the emulator; -1 = random"),
    "planner": ("gryffin_planner", "the planner node whose proposals this emulator runs (a name relative to this "
                                   "node's namespace, or absolute)"),
}
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
        self.running: tuple[dict, float] | None = None
        planner = p["planner"].rstrip("/")
        if not planner:
            raise GryffinRosError("parameter 'planner' must name the planner node (default gryffin_planner)")
        self.publisher = self.create_publisher(typed.Observation, f"{planner}/observations", OBSERVATIONS_QOS)
        self.create_subscription(typed.Proposals, f"{planner}/proposals", self._on_proposals, LATCHED_QOS)
        self.create_timer(0.005, self._work)

    def _on_proposals(self, msg: typed.Proposals) -> None:
        for proposal in msg.proposals:
            experiment_id = proposal.experiment_id
            if experiment_id in self.reported:
                # announced again (the planner restarted): the report may have been lost, so send it again; a
                # planner that has it already rejects the copy as a duplicate
                self.publisher.publish(self.reported[experiment_id])
                continue
            if experiment_id in self.seen:
                continue
            try:
                params = typed.params_of(proposal.params)
            except GryffinRosError as exc:
                self.get_logger().warning(f"proposal {experiment_id}: {exc}; skipped")
                continue
            missing = [n for n in self.emulator.parameters if n not in params]
            if missing:
                self.get_logger().warning(f"proposal {experiment_id} lacks {missing}; skipped")
                continue
            self.seen.add(experiment_id)
            self.queue.append({"experiment_id": experiment_id, "params": params})

    def _work(self) -> None:
        if self.running is None:
            if not self.queue:
                return
            self.running = (self.queue.popleft(), time.monotonic())
        proposal, started = self.running
        if time.monotonic() - started < self.experiment_time:
            return
        self.running = None
        try:
            result = self.emulator.measure(proposal["params"])
        except (KeyError, TypeError, ValueError) as exc:
            self.get_logger().warning(f"cannot emulate {proposal['experiment_id']}: {exc!r}; reported as failed")
            result = None
        failed = result is None or self.rng.random() < self.failure_rate
        observation = typed.observation_message(proposal["experiment_id"], proposal["params"],
                                                None if failed else {k: result[k] for k in self.objectives}, result)
        self.reported[proposal["experiment_id"]] = observation
        self.publisher.publish(observation)


def _main(kind: str) -> Callable[[list[str] | None], int]:
    def main(args: list[str] | None = None) -> int:
        return run(lambda: EmulatorNode(kind), kind, args)
    return main


flow_reactor_main = _main("flow_reactor_emulator")
redox_main = _main("redox_emulator")

if __name__ == "__main__":
    sys.exit({"flow_reactor": flow_reactor_main, "redox": redox_main}[sys.argv.pop(1)](None))
