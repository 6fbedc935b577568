"""Stagnation: does a long flow-reactor campaign keep improving? The example config
(gryffin_ros/examples/flow_reactor.yaml, the default surrogate) through the Python API, the BNN emulator measuring,
several seeds; the cost of the best experiment (Chimera: X1 + X2 >= 0.9 first, then the cost) at each milestone, and
how often the best changed after the first.

    .venv/bin/python -m benchmarks.stagnation [--seeds 0-3] [--budget 1000] [--batch 10] [--milestones 100,300,1000]
                                              [--out benchmarks/results/stagnation]

Each seed seeds both the planner and the emulator's noise. `--batch` proposals per ask (the soak's 10; the paper's
runs propose 2 per ask, which makes 1000 experiments take ~5x longer here).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

from gryffin_ros.campaign import Campaign
from gryffin_ros.emulators import FlowReactorEmulator
from gryffin_ros.paths import share_path
from gryffin_ros.planner.config import load_config
from gryffin_ros.planner.merit import best_so_far

CONFIG = share_path("examples") / "flow_reactor.yaml"
YIELD = 0.9


def seeds_arg(text: str) -> list[int]:
    if "-" in text:
        first, last = text.split("-")
        return list(range(int(first), int(last) + 1))
    return [int(s) for s in text.split(",")]


def run(seed: int, budget: int, batch: int, milestones: list[int], work: Path) -> dict:
    emulator = FlowReactorEmulator(seed=seed)
    started = time.perf_counter()
    with Campaign(CONFIG, work / f"seed{seed}.sqlite", seed=seed) as campaign:
        while campaign.n_observations < budget:
            for proposal in campaign.propose(min(batch, budget - campaign.n_observations)):
                result = emulator.measure(proposal.params)
                campaign.observe({"experiment_id": proposal.experiment_id, "params": proposal.params,
                                  "objectives": {"X1_X2": result["X1_X2"], "cost": result["cost"]}})
        observations = campaign.store.observations()
    trace = best_so_far(load_config(CONFIG), observations)
    at = {m: trace[m - 1] for m in milestones if m <= len(trace)}
    changes_after = sum(1 for k in range(milestones[0], len(trace))
                        if trace[k] is not None and trace[k] is not trace[k - 1])
    last_change = max((k + 1 for k in range(1, len(trace)) if trace[k] is not trace[k - 1]), default=0)
    return {"seed": seed, "cost": {m: o.objectives["cost"] for m, o in at.items()},
            "yield_met": {m: o.objectives["X1_X2"] >= YIELD for m, o in at.items()},
            "changes_after_first_milestone": changes_after, "last_improvement_at": last_change,
            "wall_s": time.perf_counter() - started}


def summary(results: list[dict], milestones: list[int]) -> str:
    lines = ["| seed | " + " | ".join(f"cost at {m}" for m in milestones)
             + f" | best changed after {milestones[0]} | last change at |",
             "|---" * (len(milestones) + 3) + "|"]
    for r in results:
        cells = [f"{r['cost'][m]:.5f}" + ("" if r["yield_met"][m] else " (X1+X2 < 0.9)") for m in milestones]
        lines.append(f"| {r['seed']} | " + " | ".join(cells)
                     + f" | {r['changes_after_first_milestone']} | {r['last_improvement_at']} |")
    means = []
    for m in milestones:
        values = [r["cost"][m] for r in results]
        se = statistics.stdev(values) / len(values) ** 0.5 if len(values) > 1 else float("nan")
        means.append(f"{statistics.mean(values):.5f} ± {se:.5f}")
    lines.append("| mean ± s.e. | " + " | ".join(means) + " | | |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="0-3")
    parser.add_argument("--budget", type=int, default=1000)
    parser.add_argument("--batch", type=int, default=10)
    parser.add_argument("--milestones", default="100,300,1000")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "stagnation")
    args = parser.parse_args(argv)
    milestones = sorted(int(m) for m in args.milestones.split(",") if int(m) <= args.budget)
    if not milestones:
        parser.error("no milestone within the budget")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in seeds_arg(args.seeds):
            results.append(run(seed, args.budget, args.batch, milestones, Path(tmp)))
            print(json.dumps(results[-1]), flush=True)
    command = "  .venv/bin/python -m benchmarks.stagnation " + " ".join(sys.argv[1:] if argv is None else argv)
    text = (f"Flow reactor (gryffin_ros/examples/flow_reactor.yaml, default surrogate), {args.budget} experiments "
            f"in asks of {args.batch}, Python API; cost ($/min) of the best experiment by the Chimera hierarchy:"
            f"\n\n{command}\n\n"
            + summary(results, milestones) + "\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.with_suffix(".md").write_text(text)
    args.out.with_suffix(".json").write_text(json.dumps({"command": command.strip(), "batch": args.batch,
                                                         "results": results}, indent=1) + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
