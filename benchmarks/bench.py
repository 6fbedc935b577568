"""The paper's benchmark surfaces with the paper's protocol (one proposal per ask, the planner told each result),
parallel over seeds and resumable (one JSON record per run in --out); one summary line per surface and strategy.

    python -m benchmarks.bench --surface branin,slope [--strategy adam,genetic,gp,auto,random,deap] [--seeds 10]
        [--budget N] [--variant ordinal|categorical] [--processes N] [--out bench-results] [--json FILE]

Exit code 1 when any proposal violated a known constraint.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from benchmarks.runner import STRATEGIES, Job, format_summary, run_jobs, summarize
from benchmarks.surfaces import SURFACES


def bench(args: argparse.Namespace) -> int:
    """Run (or resume) the paper's benchmarks and print one summary line per surface and strategy."""
    surfaces = [s.strip() for s in args.surface.split(",") if s.strip()]
    strategies = [s.strip() for s in args.strategy.split(",") if s.strip()]
    unknown = [s for s in surfaces if s not in SURFACES] + [s for s in strategies if s not in STRATEGIES]
    if unknown or not surfaces or not strategies:
        print(f"error: unknown surface/strategy {unknown}; surfaces: {', '.join(SURFACES)}; "
              f"strategies: {', '.join(STRATEGIES)}", file=sys.stderr)
        return 2
    groups: dict[tuple[str, str], list[Job]] = {}
    for name in surfaces:
        surface = SURFACES[name]
        budget = args.budget or (100 if surface.kind == "continuous" else 441)
        variant = args.variant if surface.kind == "discrete" else None
        for strategy in strategies:
            jobs = [Job(name, strategy, seed, budget, variant) for seed in range(args.first_seed,
                                                                                 args.first_seed + args.seeds)]
            groups[(name, jobs[0].label)] = jobs
    all_jobs = [job for jobs in groups.values() for job in jobs]

    def progress(job: Job, record: dict) -> None:
        result = (f"optimum at {record['evaluations_to_optimum']}" if record["evaluations_to_optimum"]
                  else f"best {min(record['values'], default=float('nan')):.4g}")
        flag = f"  VIOLATIONS {record['violations']}" if record["violations"] else ""
        flag += f"  ERROR {record['error']}" if record.get("error") else ""
        print(f"{job.surface} {job.label} seed {job.seed}: {result} ({record['seconds']:.1f} s){flag}", flush=True)

    run_jobs(all_jobs, Path(args.out), args.processes, progress)
    summaries = {}
    for (name, label), jobs in groups.items():
        summary = summarize(json.loads(job.path(Path(args.out)).read_text()) for job in jobs)
        summaries[f"{name}/{label}"] = summary
        print(format_summary(name, label, summary))
    if args.json:
        Path(args.json).write_text(json.dumps(summaries, indent=1))
    return 1 if any(s["violations"] for s in summaries.values()) else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--surface", required=True, help="surface name(s), comma separated (e.g. branin,slope)")
    parser.add_argument("--strategy", default="adam",
                        help="adam, genetic (kde), gp, auto, portfolio, default, random, deap (comma separated)")
    parser.add_argument("--seeds", type=int, default=10, help="number of runs (seeds from --first-seed)")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--budget", type=int, default=None,
                        help="evaluations per run (default 100; discrete: 441, stopping at the optimum)")
    parser.add_argument("--variant", choices=("ordinal", "categorical"), default="ordinal",
                        help="discrete surfaces: ordered options (1-d descriptor) or plain categorical options")
    parser.add_argument("--processes", type=int, default=None, help="parallel runs (default: all cores)")
    parser.add_argument("--out", default="bench-results", help="folder of per-run results (default bench-results)")
    parser.add_argument("--json", help="also write the summaries to this JSON file")
    args = parser.parse_args(argv)
    if args.seeds < 1 or (args.budget is not None and args.budget < 1):
        parser.error("--seeds and --budget must be at least 1")
    return bench(args)


if __name__ == "__main__":
    sys.exit(main())
