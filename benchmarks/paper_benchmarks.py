"""The paper's eight constrained benchmarks: our runs (from `python -m benchmarks.bench`) next to the published ones.

    python -m benchmarks.bench --surface branin,schwefel,dejong,discreteackley --strategy adam,genetic,random,deap \\
        --seeds 100 --out bench-results
    python -m benchmarks.bench --surface slope,sphere,michalewicz,camel --strategy adam,genetic,random,deap \\
        --seeds 100 --out bench-results
    python -m benchmarks.paper_benchmarks [--runs bench-results] [--data ../shared/data] [--out benchmarks/results]

Published runs (../shared/data/gkc_benchmarks): continuous surfaces from the per-run traces, whose objective values are
recomputed from the recorded points with our surface definitions (this sidesteps the sign-flipped Dragonfly values);
discrete surfaces from the per-run evaluation counts in benchmarks_known/cat-*/summary.csv (cat-dejong is Sphere).
Writes paper_benchmarks.md, paper_benchmarks.json, paper_continuous.png and paper_discrete.png.
"""

from __future__ import annotations

import argparse
import csv
import gzip
import json
import math
import statistics
from collections import defaultdict
from pathlib import Path

import numpy as np

from benchmarks.runner import STRATEGIES, best_so_far, load_records, summarize
from benchmarks.surfaces import CONTINUOUS_SURFACES, DISCRETE_SURFACES

CONTINUOUS = ("branin", "schwefel", "dejong", "discreteackley")
DISCRETE = ("slope", "sphere", "michalewicz", "camel")
BUDGET = 100
PUBLISHED = {"random": "Random", "deap": "Genetic (DEAP)", "opt_adam": "Gryffin (Adam)",
             "opt_genetic": "Gryffin (Genetic)", "dragonfly": "Dragonfly"}
SUMMARY_COLUMNS = {"random": "Random", "deap": "Genetic (DEAP)", "gryffin_adam": "Gryffin (Adam)",
                   "gryffin_genetic": "Gryffin (Genetic)", "dragonfly": "Dragonfly"}
OURS = {"adam": "ours: Adam/Hill", "genetic": "ours: Genetic", "gp": "ours: GP", "auto": "ours: auto (GP|KDE)",
        "random": "ours: Random", "deap": "ours: DEAP"}
DISCRETE_FOLDER = {"slope": "cat-slope", "sphere": "cat-dejong", "michalewicz": "cat-michalewicz",
                   "camel": "cat-camel"}
TARGETS = {"slope": 10, "sphere": 12.5, "michalewicz": 16.5, "camel": 30,
           "branin": 0.40, "schwefel": -760, "discreteackley": 0.5, "dejong": 1.10}


def published_continuous(data: Path) -> dict[str, dict[str, list[list[float]]]]:
    """surface -> strategy -> best-so-far traces (100 iterations) recomputed from the recorded points."""
    points: dict[tuple[str, str, str], list[tuple[int, float, float]]] = defaultdict(list)
    with gzip.open(data / "gkc_benchmarks" / "DERIVED_benchmarks_known_per_run_traces.csv.gz", "rt") as f:
        for row in csv.DictReader(f):
            if row["benchmark"] in CONTINUOUS and row["strategy"] in PUBLISHED:
                points[(row["benchmark"], row["strategy"], row["run"])].append(
                    (int(row["iteration"]), float(row["x0"]), float(row["x1"])))
    traces: dict[str, dict[str, list[list[float]]]] = defaultdict(lambda: defaultdict(list))
    for (surface, strategy, _), rows in sorted(points.items()):
        rows.sort()
        x0, x1 = (np.array([r[k] for r in rows[:BUDGET]]) for k in (1, 2))
        values = CONTINUOUS_SURFACES[surface].objective(x0, x1)
        traces[surface][strategy].append(best_so_far(values.tolist(), BUDGET))
    return traces


def published_discrete(data: Path) -> dict[str, dict[str, list[float]]]:
    out: dict[str, dict[str, list[float]]] = {}
    for surface, folder in DISCRETE_FOLDER.items():
        with open(data / "gkc_benchmarks" / "benchmarks_known" / folder / "summary.csv") as f:
            rows = list(csv.DictReader(f))
        out[surface] = {column: [float(r[column]) for r in rows] for column in SUMMARY_COLUMNS}
    return out


def mean_se(xs: list[float]) -> tuple[float, float]:
    return statistics.fmean(xs), (statistics.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else 0.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=Path, default=Path("bench-results"))
    parser.add_argument("--data", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "data")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    args = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    report: dict = {"continuous": {}, "discrete": {}}
    lines = ["# The paper's constrained benchmarks: ours next to the published runs", "",
             "Produced by the commands at the top of `benchmarks/paper_benchmarks.py`. Ours: one proposal per ask, "
             "lambda alternating -1/+1, the surface's constraint given as a known constraint. Published: 100 runs per "
             "strategy from `../shared/data/gkc_benchmarks` (TensorFlow-era Gryffin; see the data README).", ""]

    # ---- continuous ----------------------------------------------------------------------------------------
    published = published_continuous(args.data)
    fig, axes = plt.subplots(1, len(CONTINUOUS), figsize=(5 * len(CONTINUOUS), 4))
    lines += ["## Continuous surfaces: best-so-far objective (mean +- s.e.) and constraint violations", "",
              "| surface | strategy | runs | @10 | @20 | @50 | @100 | regret @100 | violations | median ask |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for ax, name in zip(axes, CONTINUOUS):
        surface = CONTINUOUS_SURFACES[name]
        optimum = surface.optimum_value
        report["continuous"][name] = {"optimum": optimum, "target": TARGETS[name]}
        for strategy in STRATEGIES:
            records = load_records(args.runs, name, strategy, BUDGET)
            if not records:
                continue
            summary = summarize(records)
            report["continuous"][name][f"ours/{strategy}"] = summary
            cells = " | ".join(f"{summary[f'best_at_{k}']:.4g} +- {summary[f'best_at_{k}_se']:.2g}"
                               for k in (10, 20, 50, 100))
            lines.append(f"| {name} | **{OURS[strategy]}** | {summary['runs']} | {cells} | "
                         f"{summary['regret_at_100']:.4g} | {summary['violations']} | "
                         f"{summary['median_ask_seconds'] * 1000:.0f} ms |")
            regret = np.mean([best_so_far(r["values"], BUDGET) for r in records], axis=0) - optimum
            ax.plot(np.arange(1, BUDGET + 1), np.maximum(regret, 1e-6), label=OURS[strategy], lw=2)
        for strategy, label in PUBLISHED.items():
            traces = published.get(name, {}).get(strategy)
            if not traces:
                continue
            stats = {k: mean_se([t[k - 1] for t in traces]) for k in (10, 20, 50, 100)}
            report["continuous"][name][f"published/{strategy}"] = {
                "runs": len(traces), **{f"best_at_{k}": v[0] for k, v in stats.items()},
                **{f"best_at_{k}_se": v[1] for k, v in stats.items()}}
            cells = " | ".join(f"{m:.4g} +- {s:.2g}" for m, s in stats.values())
            lines.append(f"| {name} | {label} (published) | {len(traces)} | {cells} | "
                         f"{stats[100][0] - optimum:.4g} | | |")
            ax.plot(np.arange(1, BUDGET + 1), np.maximum(np.mean(traces, axis=0) - optimum, 1e-6),
                    label=f"{label} (pub.)", ls="--", lw=1)
        ax.set_yscale("log")
        ax.set_title(f"{name} (optimum {optimum:.4g}; target <= {TARGETS[name]})")
        ax.set_xlabel("evaluations")
        ax.set_ylabel("regret of best-so-far (mean)")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out / "paper_continuous.png", dpi=110)
    plt.close(fig)

    # ---- discrete ------------------------------------------------------------------------------------------
    published_counts = published_discrete(args.data)
    fig, axes = plt.subplots(1, len(DISCRETE), figsize=(5 * len(DISCRETE), 4.5))
    lines += ["", "## Discrete surfaces: evaluations until the constrained optimum is evaluated", "",
              "| surface | strategy | runs | mean +- s.e. | median | found | violations | median ask |",
              "|---|---|---|---|---|---|---|---|"]
    for ax, name in zip(axes, DISCRETE):
        report["discrete"][name] = {"optimum": list(DISCRETE_SURFACES[name].optimum()), "target": TARGETS[name]}
        boxes, labels = [], []
        for strategy in STRATEGIES:
            records = load_records(args.runs, name, strategy, 441)
            if not records:
                continue
            summary = summarize(records)
            report["discrete"][name][f"ours/{strategy}"] = summary
            lines.append(f"| {name} | **{OURS[strategy]}** | {summary['runs']} | {summary['evaluations_mean']:.1f} +- "
                         f"{summary['evaluations_se']:.1f} | {summary['evaluations_median']:g} | "
                         f"{summary['found']}/{summary['runs']} | {summary['violations']} | "
                         f"{summary['median_ask_seconds'] * 1000:.0f} ms |")
            boxes.append([r["evaluations_to_optimum"] or 441 for r in records])
            labels.append(OURS[strategy].replace("ours: ", "ours\n"))
        for column, label in SUMMARY_COLUMNS.items():
            counts = published_counts[name][column]
            m, s = mean_se(counts)
            report["discrete"][name][f"published/{column}"] = {"runs": len(counts), "evaluations_mean": m,
                                                                 "evaluations_se": s,
                                                                 "evaluations_median": statistics.median(counts)}
            lines.append(f"| {name} | {label} (published) | {len(counts)} | {m:.1f} +- {s:.1f} | "
                         f"{statistics.median(counts):g} | | | |")
            boxes.append(counts)
            labels.append(label.replace(" (", "\n("))
        ax.boxplot(boxes, showmeans=True)
        ax.set_xticks(range(1, len(labels) + 1), labels, fontsize=6, rotation=90)
        ax.axhline(TARGETS[name], color="red", lw=0.8, ls=":")
        ax.set_yscale("log")
        ax.set_title(f"{name} (target mean <= {TARGETS[name]})")
        ax.set_ylabel("evaluations to optimum")
    fig.tight_layout()
    fig.savefig(args.out / "paper_discrete.png", dpi=110)
    plt.close(fig)

    (args.out / "paper_benchmarks.md").write_text("\n".join(lines) + "\n")
    (args.out / "paper_benchmarks.json").write_text(json.dumps(report, indent=1))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
