"""The paper's two applications, many seeds, next to the paper's own runs (../shared/data):

- flow reactor (gryffin_ros/examples/flow_reactor.yaml, BNN emulator): best-so-far by the Chimera hierarchy
  (X1 + X2 >= 0.9, then cost); reported: cost of the best experiment at iteration 100 and how many runs reached
  X1 + X2 >= 0.9.
- redox candidates (gryffin_ros/examples/redox_flow_battery.yaml, DFT lookup): experiments until the best
  synthesizable candidate (R1_0, R3_7, R4_7, R5_0) is measured, with dynamic descriptors, static descriptors and
  none (the example's three sampling strategies), and `dynamic-2s`: dynamic descriptors with the paper's two
  alternating strategies.

    python -m benchmarks.applications [--seeds 20] [--processes 2] [--data ../shared/data] [--out benchmarks/results]
        [--flow default,genetic,adam,gp,auto]   flow-reactor variants: the example as shipped (the default
                                                surrogate, Genetic); the kernel density (the paper's model) with the
                                                Genetic or the Adam optimizer; the GP or auto surrogate with Adam
        [--redox dynamic,static,no,dynamic-2s,dynamic-kde]  redox variants (default: the first three); all but
                                                dynamic-kde (the paper's kernel density) use the default surrogate

Per-run results go to <out>/applications_runs.json (resumable); the table to applications.md, plots to
applications_flow.png and applications_redox.png.
"""

from __future__ import annotations

import argparse
import csv
import gzip
import json
import statistics
from collections import defaultdict
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from gryffin_ros.paths import share_path

BUDGET = 100
BEST_REDOX = ("R1_0", "R3_7", "R4_7", "R5_0")
REDOX_VARIANTS = {"dynamic": "dynamic descriptors", "static": "static descriptors", "no": "no descriptors",
                  "dynamic-2s": "dynamic descriptors, 2 strategies",
                  "dynamic-kde": "dynamic descriptors, kernel density (paper's model)"}
# flow-reactor variants: overrides of the example's `general` section, and their label
FLOW_VARIANTS = {"default": ({}, "gryffin_ros (default surrogate, Genetic)"),
                 "genetic": ({"acquisition_optimizer": "genetic", "surrogate": "kde"}, "gryffin_ros (kde, Genetic)"),
                 "adam": ({"acquisition_optimizer": "adam", "surrogate": "kde"}, "gryffin_ros (kde, Adam)"),
                 "gp": ({"acquisition_optimizer": "adam", "surrogate": "gp"}, "gryffin_ros (GP, Adam)"),
                 "auto": ({"acquisition_optimizer": "adam", "surrogate": "auto"}, "gryffin_ros (auto, Adam)")}


def redox_config(variant: str) -> dict:
    from gryffin_ros.planner.config import read_config
    config = read_config(share_path("examples") / "redox_flow_battery.yaml")
    config["general"]["auto_desc_gen"] = variant.startswith("dynamic")
    if variant == "dynamic-2s":
        config["general"]["sampling_strategies"] = 2
    if variant == "dynamic-kde":
        config["general"]["surrogate"] = "kde"
    if variant == "no":
        for parameter in config["parameters"]:
            parameter["options"] = list(parameter.pop("descriptors"))
    return config


def run(job: tuple[str, str, int]) -> dict:
    import torch

    from gryffin_ros.emulators import FlowReactorEmulator, RedoxEmulator
    from gryffin_ros.planner import Planner
    from gryffin_ros.planner.config import load_config, read_config
    torch.set_num_threads(1)
    app, variant, seed = job
    examples = share_path("examples")
    if app == "flow":
        config = read_config(examples / "flow_reactor.yaml")
        config.setdefault("general", {}).update(FLOW_VARIANTS[variant][0])
        planner, emulator = Planner(load_config(config, examples), seed=seed), FlowReactorEmulator(seed=seed)
    else:
        planner, emulator = Planner(load_config(redox_config(variant), examples), seed=seed), RedoxEmulator()
    names = [o.name for o in planner.objectives]
    trace, found = [], None
    for iteration in range(1, BUDGET + 1):
        (proposal,) = planner.ask()
        result = emulator.measure(proposal.params)
        planner.tell({**proposal.params, **{k: result[k] for k in names}, "experiment_id": proposal.experiment_id})
        trace.append(planner.best().objectives)
        if app == "redox" and tuple(proposal.params.values()) == BEST_REDOX:
            found = iteration
            break
    return {"app": app, "variant": variant, "seed": seed, "trace": trace, "found": found}


def chimera_best_traces(rows: list[dict], objectives) -> list[dict]:
    """Best-so-far (by Chimera over the experiments so far) of one published run."""
    from gryffin_ros.planner.chimera import Chimera
    chimera, out = Chimera(objectives), []
    values = np.array([[r["obj0"], r["obj1"]] for r in rows], dtype=float)
    for i in range(1, len(rows) + 1):
        out.append(values[int(np.argmin(chimera.merits(values[:i])))])
    return out


def paper_flow(data: Path) -> dict[str, list[np.ndarray]]:
    from gryffin_ros.planner.config import Objective
    objectives = [Objective("X1_X2", "max", 0.9, True), Objective("cost", "min")]
    runs: dict[tuple[str, str], list[dict]] = defaultdict(list)
    with gzip.open(data / "gkc_fullerenes" / "DERIVED_per_run_traces.csv.gz", "rt") as handle:
        for row in csv.DictReader(handle):
            if row["obj0"] and row["obj1"]:
                runs[(row["strategy"], row["run"])].append({"obj0": float(row["obj0"]), "obj1": float(row["obj1"])})
    traces: dict[str, list[np.ndarray]] = defaultdict(list)
    for (strategy, _), rows in sorted(runs.items()):
        traces[strategy].append(np.array(chimera_best_traces(rows[:BUDGET], objectives)))
    return traces


def paper_redox(data: Path) -> dict[str, list[int | None]]:
    found: dict[tuple[str, str], int | None] = {}
    with gzip.open(data / "gkc_redox_batteries" / "DERIVED_per_run_traces.csv.gz", "rt") as handle:
        for row in csv.DictReader(handle):
            key = (row["strategy"], row["run"])
            found.setdefault(key, None)
            candidate = (row["r1_label"], row["r3_label"], row["r4_label"], row["r5_label"])
            if candidate == BEST_REDOX and found[key] is None and int(row["iteration"]) <= BUDGET:
                found[key] = int(row["iteration"])
    out: dict[str, list[int | None]] = defaultdict(list)
    for (strategy, _), iteration in found.items():
        out[strategy].append(iteration)
    return out


def redox_row(name: str, found: list[int | None]) -> str:
    hits = [f for f in found if f is not None]
    median = statistics.median([f if f is not None else BUDGET + 1 for f in found])
    shown = f"{median:g}" if median <= BUDGET else f"> {BUDGET}"
    among = f"{statistics.median(hits):g}" if hits else "-"
    return f"| {name} | {len(found)} | {100 * len(hits) / len(found):.0f} % | {shown} | {among} |"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--processes", type=int, default=2)
    parser.add_argument("--data", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "data")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--flow", default="genetic",
                        help=f"flow-reactor variants, comma separated: {', '.join(FLOW_VARIANTS)}")
    parser.add_argument("--redox", default="dynamic,static,no",
                        help=f"redox variants, comma separated: {', '.join(REDOX_VARIANTS)}")
    args = parser.parse_args()
    flow_variants = [v for v in args.flow.split(",") if v]
    redox_variants = [v for v in args.redox.split(",") if v]
    if set(flow_variants) - set(FLOW_VARIANTS):
        parser.error(f"--flow: choose from {', '.join(FLOW_VARIANTS)}")
    if set(redox_variants) - set(REDOX_VARIANTS):
        parser.error(f"--redox: choose from {', '.join(REDOX_VARIANTS)}")
    args.out.mkdir(parents=True, exist_ok=True)
    store = args.out / "applications_runs.json"
    done = {(r["app"], r["variant"], r["seed"]): r for r in (json.loads(store.read_text()) if store.exists() else [])}
    jobs = [("flow", v, s) for v in flow_variants for s in range(args.seeds)]
    jobs += [("redox", v, s) for v in redox_variants for s in range(args.seeds)]
    with Pool(args.processes) as pool:
        for result in pool.imap_unordered(run, [j for j in jobs if j not in done]):
            done[(result["app"], result["variant"], result["seed"])] = result
            store.write_text(json.dumps(list(done.values())))
    ours = [r for key, r in done.items() if key in set(jobs)]

    flows = {FLOW_VARIANTS[v][1]: [np.array([[t["X1_X2"], t["cost"]] for t in r["trace"]]) for r in ours
                                if r["app"] == "flow" and r["variant"] == v] for v in flow_variants}
    paper = paper_flow(args.data)
    lines = [f"Flow reactor, {BUDGET} experiments: cost ($/min) of the best experiment by the Chimera hierarchy at "
             "iteration 100 (mean ± s.e.), and runs whose best reached X1 + X2 >= 0.9.", "",
             "| strategy | runs | cost at 100 | X1 + X2 >= 0.9 |", "|---|---|---|---|"]
    for name, traces in list(flows.items()) + [(f"paper: {k}", v) for k, v in sorted(paper.items())]:
        final = np.array([t[-1] for t in traces])
        se = final[:, 1].std(ddof=1) / np.sqrt(len(final)) if len(final) > 1 else float("nan")
        lines.append(f"| {name} | {len(final)} | {final[:, 1].mean():.5f} ± {se:.5f} | "
                     f"{100 * (final[:, 0] >= 0.9).mean():.0f} % |")
    lines += ["", f"Redox candidates: runs that measured the best synthesizable candidate within {BUDGET} experiments "
              "and the median number of experiments to it.", "",
              "| strategy | runs | found | median experiments (all runs) | median (runs that found it) |",
              "|---|---|---|---|---|"]
    for variant in redox_variants:
        lines.append(redox_row(f"gryffin_ros, {REDOX_VARIANTS[variant]}",
                               [r["found"] for r in ours if r["app"] == "redox" and r["variant"] == variant]))
    for strategy, found in sorted(paper_redox(args.data).items()):
        lines.append(redox_row(f"paper: {strategy}", found))
    text = "\n".join(lines) + "\n"
    (args.out / "applications.md").write_text(text)
    print(text)
    plot(flows, paper, ours, paper_redox(args.data), redox_variants, args.out)


def plot(flows, paper, ours, paper_found, redox_variants, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, traces, style in ([(k, v, "-") for k, v in flows.items()]
                                + [(f"paper {k}", v, "--") for k, v in paper.items()]):
        length = min(len(t) for t in traces)
        ax.plot(range(1, length + 1), np.mean([t[:length, 1] for t in traces], axis=0), style, label=name)
    ax.set(xlabel="experiment", ylabel="cost of best ($/min)", yscale="log", title="Flow reactor (mean best-so-far)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "applications_flow.png", dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 4))
    curves = {f"gryffin_ros {v}": [r["found"] for r in ours if r["app"] == "redox" and r["variant"] == v]
              for v in redox_variants}
    curves.update({f"paper {k}": v for k, v in paper_found.items()})
    for name, found in curves.items():
        hits = [sum(1 for f in found if f is not None and f <= k) / len(found) for k in range(1, BUDGET + 1)]
        ax.plot(range(1, BUDGET + 1), hits, "-" if name.startswith("gryffin_ros") else "--", label=name)
    ax.set(xlabel="experiment", ylabel="fraction of runs with the best candidate", title="Redox candidates")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "applications_redox.png", dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
