"""`gryffin-ros` command line: run a constrained campaign from the Python API and print its progress."""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence
from importlib import resources

from .planner import GryffinRosError, Planner


def toy_flow_yield(params: dict) -> float:
    """A smooth stand-in for the flow reactor: best near a 1:1.3 flow ratio, ~240 uL/min in total and 135 degC."""
    total, ratio = params["F_C"] + params["F_S"], params["F_S"] / max(params["F_C"], 1e-9)
    return (math.exp(-((total - 240.0) / 90.0) ** 2) * math.exp(-(math.log(ratio / 1.3)) ** 2 / 0.2)
            * math.exp(-((params["T"] - 135.0) / 25.0) ** 2))


def demo(args: argparse.Namespace) -> int:
    config = args.config or resources.files("gryffin_ros").joinpath("examples/flow_reactor_toy.yaml")
    planner = Planner(str(config), seed=args.seed)
    objective = planner.objectives[0]
    print(f"campaign '{planner.config.name}': {planner.space.dim} parameters, feasible fraction "
          f"{planner.feasible_fraction.value:.3f} ({planner.feasible_fraction.method}), budget {args.budget}")
    for i in range(1, args.budget + 1):
        start = time.perf_counter()
        (proposal,) = planner.ask(1)
        elapsed = time.perf_counter() - start
        value = toy_flow_yield(proposal.params)
        planner.tell({**proposal.params, objective.name: value, "experiment_id": proposal.experiment_id})
        best = planner.best().objectives[objective.name]
        shown = "  ".join(f"{k}={v:7.2f}" for k, v in proposal.params.items())
        print(f"[{i:3d}/{args.budget}] {shown}  -> {objective.name} {value:.3f}  best {best:.3f}  "
              f"(ask {elapsed:.2f} s)", flush=True)
    print(f"best: {planner.best().params} -> {planner.best().objectives}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="gryffin-ros", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("demo", help="run a constrained toy campaign through the Python API")
    run.add_argument("--config", help="campaign config (YAML/JSON); default: the packaged flow-reactor toy")
    run.add_argument("--budget", type=int, default=30, help="number of experiments (default 30)")
    run.add_argument("--seed", type=int, default=0)
    run.set_defaults(handler=demo)
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except GryffinRosError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
