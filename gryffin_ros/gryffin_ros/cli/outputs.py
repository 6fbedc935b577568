"""What a campaign leaves behind: the best-so-far plot and the store exported as CSV / JSON."""

from __future__ import annotations

import argparse
import sys
import threading
from pathlib import Path

import numpy as np

from ..nodes.supervisor import signals_as_interrupt
from ..planner.chimera import hierarchy, tolerance_line
from ..planner.config import PlannerConfig
from ..planner.merit import best_so_far
from ..storage import CampaignStore


def plot(store: CampaignStore, config: PlannerConfig, path: Path) -> None:
    """Per objective: every experiment as a point (failed ones marked on the axis), the objective of the best
    experiment so far (by the campaign's merit, Chimera included) as a line, and the Chimera tolerance; axes with
    the config's units."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    observations = store.observations()
    bests = best_so_far(config, observations)
    x = np.arange(1, len(observations) + 1)
    several = len(config.objectives) > 1
    fig, axes = plt.subplots(1, len(config.objectives), figsize=(5.2 * len(config.objectives), 4.0), squeeze=False)
    for ax, objective in zip(axes[0], config.objectives):
        values = np.array([np.nan if o.objectives[objective.name] is None else o.objectives[objective.name]
                           for o in observations], dtype=float)
        best = np.array([np.nan if b is None else b.objectives[objective.name] for b in bests], dtype=float)
        ax.scatter(x, values, s=14, color="0.55", label="experiment", zorder=2)
        failed = ~np.isfinite(values)
        if failed.any():
            ax.plot(x[failed], np.full(failed.sum(), 0.0), "x", color="tab:red", transform=ax.get_xaxis_transform(),
                    clip_on=False, label="failed")
        ax.plot(x, best, drawstyle="steps-post", color="tab:blue", lw=2, label="best so far", zorder=3)
        line = tolerance_line(objective, values) if several else None
        if line is not None:
            ax.axhline(line, color="tab:orange", ls="--", lw=1.2,
                       label=f"tolerance {'>=' if objective.goal == 'max' else '<='} {line:.4g}")
        ax.set_xlabel("experiment")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_ylabel(f"{config.label(objective.name)}, goal: {objective.goal}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    title = f"campaign '{config.name}': {len(observations)} experiments"
    if several:  # why a best value can get worse: the best is the Chimera-best, not the best of each objective
        title += f"\nbest = {hierarchy(config)}"
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def export(args: argparse.Namespace) -> int:
    """The store's experiments as CSV and/or JSON; with neither option, both, next to the store (STORE.csv/.json)."""
    store = CampaignStore.open_existing(args.store)
    if not args.csv and not args.json:
        args.csv, args.json = (str(Path(args.store).with_suffix(suffix)) for suffix in (".csv", ".json"))
    if args.csv:
        print(f"{store.export_csv(args.csv)} observation(s) written to {args.csv}")
    if args.json:
        print(f"{store.export_json(args.json)} observation(s) written to {args.json}")
    store.close()
    return 0


def dashboard(args: argparse.Namespace) -> int:
    """Serve the store's dashboard until Ctrl-C (or SIGTERM, SIGHUP)."""
    from ..dashboard import start
    server = start(args.store, args.host, args.port, Path(args.config).resolve().parent if args.config else None)
    print(f"dashboard of {args.store}: {server.url}  (Ctrl-C to stop)", flush=True)
    if not server.loopback:
        print(f"warning: {args.host} makes the page reachable from other machines, without authentication",
              file=sys.stderr)
    # Ctrl-C, SIGTERM and SIGHUP stop it, set here rather than left to Python's default: a process started in the
    # background of a script inherits SIGINT ignored, and would not stop on Ctrl-C
    with signals_as_interrupt():
        try:
            threading.Event().wait()
        except KeyboardInterrupt:
            pass
        finally:
            server.close()
    return 0
