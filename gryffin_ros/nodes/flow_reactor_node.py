"""ROS 2 node `flow_reactor_emulator`: runs each proposed experiment through the flow-reactor emulator and publishes
one observation per experiment (X0..X3, X1+X2 and the cost), optionally after a simulated experiment time and with
injected failures (objectives null)."""

from __future__ import annotations

import sys
import time
from collections import deque

import numpy as np
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from std_msgs.msg import String

from .. import messages
from ..emulators import FlowReactorEmulator
from ..emulators.flow_reactor import OUTPUTS
from ..planner import GryffinRosError
from .qos import LATCHED_QOS, OBSERVATIONS_QOS
from .runner import run

PARAMETERS = {
    "experiment_time_s": (0.0, "simulated duration of one experiment, in seconds"),
    "failure_rate": (0.0, "probability that an experiment fails (reported with objectives null)"),
    "seed": (-1, "random seed of the emulator; -1 = random"),
    "parameters": (["F_C", "F_S", "T"], "names of the C60 flow, sultine flow and temperature parameters"),
    "objectives": (["X1_X2"], "outputs reported as objectives, any of X0 X1 X2 X3 X1_X2 cost"),
}


class FlowReactorNode(Node):
    def __init__(self) -> None:
        super().__init__("flow_reactor_emulator")
        for name, (default, description) in PARAMETERS.items():
            self.declare_parameter(name, default, ParameterDescriptor(description=description))
        p = {name: self.get_parameter(name).value for name in PARAMETERS}
        if not 0.0 <= p["failure_rate"] <= 1.0:
            raise GryffinRosError(f"parameter 'failure_rate' must be in [0, 1], got {p['failure_rate']}")
        if p["experiment_time_s"] < 0:
            raise GryffinRosError(f"parameter 'experiment_time_s' must be >= 0, got {p['experiment_time_s']}")
        if len(p["parameters"]) != 3:
            raise GryffinRosError("parameter 'parameters' must name three parameters: C60 flow, sultine flow, T")
        unknown = set(p["objectives"]) - set(OUTPUTS)
        if unknown or not p["objectives"]:
            raise GryffinRosError(f"parameter 'objectives' must list outputs among {list(OUTPUTS)}, got "
                                  f"{list(p['objectives'])}")
        self.experiment_time = p["experiment_time_s"]
        self.failure_rate = p["failure_rate"]
        self.names, self.objectives = list(p["parameters"]), list(p["objectives"])
        seed = None if p["seed"] < 0 else p["seed"]
        self.emulator = FlowReactorEmulator(seed=seed)
        self.rng = np.random.default_rng(None if seed is None else seed + 1)
        self.queue: deque[dict] = deque()
        self.seen: set[str] = set()
        self.running: tuple[dict, float] | None = None
        self.publisher = self.create_publisher(String, "/gryffin_planner/observations", OBSERVATIONS_QOS)
        self.create_subscription(String, "/gryffin_planner/proposals", self._on_proposals, LATCHED_QOS)
        self.create_timer(0.005, self._work)

    def _on_proposals(self, msg: String) -> None:
        try:
            document = messages.parse("proposals", msg.data)
        except GryffinRosError as exc:
            self.get_logger().warning(f"ignoring proposals message: {exc}")
            return
        for proposal in document["proposals"]:
            if proposal["experiment_id"] in self.seen:
                continue
            missing = [n for n in self.names if not isinstance(proposal["params"].get(n), (int, float))]
            if missing:
                self.get_logger().warning(f"proposal {proposal['experiment_id']} lacks numeric {missing}; skipped")
                continue
            self.seen.add(proposal["experiment_id"])
            self.queue.append(proposal)

    def _work(self) -> None:
        if self.running is None:
            if not self.queue:
                return
            self.running = (self.queue.popleft(), time.monotonic())
        proposal, started = self.running
        if time.monotonic() - started < self.experiment_time:
            return
        self.running = None
        params = proposal["params"]
        result = self.emulator.run(*(float(params[n]) for n in self.names)).as_dict()
        failed = self.rng.random() < self.failure_rate
        observation = {"experiment_id": proposal["experiment_id"], "params": params,
                       "objectives": None if failed else {k: result[k] for k in self.objectives}, "meta": result}
        self.publisher.publish(String(data=messages.dump("observation", observation)))


def main(args: list[str] | None = None) -> int:
    return run(FlowReactorNode, "flow_reactor_emulator", args)


if __name__ == "__main__":
    sys.exit(main())
