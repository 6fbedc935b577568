"""What a campaign leaves behind: the best-so-far plot and the store exported as CSV / JSON."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..planner import Planner
from ..planner.config import PlannerConfig
from ..planner.progress import best_so_far
from ..storage import CampaignStore


def plot(store: CampaignStore, config: PlannerConfig, path: Path) -> None:
    """The objectives of the best experiment so far (by the campaign's merit, Chimera included) per experiment."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    bests = best_so_far(Planner(config, seed=0), store.observations())
    values = np.array([[np.nan if best is None else best.objectives[obj.name] for obj in config.objectives]
                       for best in bests])
    fig, axes = plt.subplots(1, len(config.objectives), figsize=(5 * len(config.objectives), 3.6), squeeze=False)
    for k, (ax, objective) in enumerate(zip(axes[0], config.objectives)):
        ax.plot(range(1, len(values) + 1), values[:, k], drawstyle="steps-post", color="tab:blue")
        ax.set_xlabel("experiment")
        ax.set_ylabel(f"{objective.name} ({objective.goal})")
        ax.grid(alpha=0.3)
    fig.suptitle(f"campaign '{config.name}': the best experiment so far")
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
