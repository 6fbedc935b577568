"""`gryffin-ros`: run a closed-loop campaign — flow reactor or redox candidates — with the planner node and an
emulator node over ROS 2 (or the Python API alone with --no-ros), export a campaign store to CSV/JSON, and rebuild a
store from a recorded bag."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ..planner import GryffinRosError
from .outputs import dashboard, export
from .run import campaign


def import_command(args: argparse.Namespace) -> int:
    from .bag_import import import_bag  # rosbags is loaded only for this command

    count = import_bag(args.bag, args.out, args.config)
    print(f"{count} observation(s) from {args.bag} into {args.out}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="gryffin-ros", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("campaign", help="run a closed-loop flow-reactor campaign (default: the packaged example)")
    run.add_argument("--config", help="campaign config (YAML/JSON); default: examples/flow_reactor.yaml")
    run.add_argument("--budget", type=int, default=30, help="number of experiments (default 30)")
    run.add_argument("--out", help="output folder (default: a new campaign-<name>-<time> folder here)")
    run.add_argument("--seed", type=int, default=None, help="seed of planner and emulator (default random)")
    run.add_argument("--experiment-time", type=float, default=0.0, help="emulated seconds per experiment")
    run.add_argument("--domain-id", type=int, default=None, help="ROS_DOMAIN_ID (default: from the environment)")
    run.add_argument("--no-ros", action="store_true", help="run planner and emulator in this process, no ROS")
    run.add_argument("--seeds", type=int, default=None,
                     help="run N campaigns (seeds from --seed, default 0) into <out>/seed-<k>/, with a summary")
    run.add_argument("--noise", action="store_true", help="redox emulator: add the published noise to DFT values")
    run.add_argument("--dashboard", type=int, default=None, metavar="PORT",
                     help="serve the campaign's live page on this port of 127.0.0.1 while it runs (0: any free port)")
    run.add_argument("--record", action="store_true",
                     help="record the planner node's messages into a ROS 2 bag <out>/bag (rosbag2 layout, MCAP; "
                          "docs/ros.md, Recording a campaign)")
    run.set_defaults(handler=campaign)
    exp = sub.add_parser("export", help="write a campaign store's experiments as CSV and/or JSON (default: both, "
                                        "next to the store)")
    exp.add_argument("store", help="campaign SQLite file (may belong to a campaign still running)")
    exp.add_argument("--csv", help="CSV file to write")
    exp.add_argument("--json", help="JSON file to write")
    exp.set_defaults(handler=export)
    imp = sub.add_parser("import", help="rebuild a campaign store from a bag the planner node recorded (-p record:=BAG "
                                        "or campaign --record)")
    imp.add_argument("bag", help="the bag folder (rosbag2 layout: metadata.yaml and .mcap files)")
    imp.add_argument("--out", required=True, help="the new campaign store (SQLite file; must not exist)")
    imp.add_argument("--config", help="the campaign's config, when the bag does not hold it (default: the bag's)")
    imp.set_defaults(handler=import_command)
    board = sub.add_parser("dashboard", help="serve a live, read-only page of a campaign store (local, offline)")
    board.add_argument("store", help="campaign SQLite file (may belong to a campaign still running)")
    board.add_argument("--port", type=int, default=8050, help="port (default 8050; 0: any free one)")
    board.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1: this machine only)")
    board.add_argument("--config", help="the campaign's config file, when its constraints name files (lookup tables) "
                                        "relative to it; default: relative to the store")
    board.set_defaults(handler=dashboard)
    args = parser.parse_args(argv)
    if (getattr(args, "budget", 1) or 1) < 1:
        parser.error("--budget must be at least 1")
    if (getattr(args, "seeds", None) or 1) < 1:
        parser.error("--seeds must be at least 1")
    try:
        return args.handler(args)
    except GryffinRosError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
