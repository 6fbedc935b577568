"""Partitions: the flow-reactor campaign across three hosts (the planner node on one, a claiming emulator node on each
of two instrument hosts; Linux network namespaces joined by a switch, `netlab.py`), with the lab network failing in
the middle of it, measured from the outside: what the store holds, what the instruments' logs say they ran.

    .venv/bin/python -m benchmarks.partitions [--budget 40] [--cuts 10,20,30] [--discovery static,subnet]
                                              [--flap-s 1,5] [--out benchmarks/results/partitions]

Scenarios: an instrument host's link cut for each of `--cuts` seconds, the planner host's link cut for as long, and
the planner's link flapping (down `a` s in every `b` s of `--flap-s`) for the whole campaign; each with every
discovery mode of `--discovery`. A cut starts when a third of the budget is stored. Per scenario:

- lost: experiments an instrument measured that are not stored when the campaign ends (must be 0);
- run twice: experiments measured by two instruments or twice by one (must be 0);
- duplicate reports: results sent again (kept until acknowledged) that the planner already had, refused as such;
- owed: experiments proposed before the link returned and not stored then; all must be stored by the end;
- recover: from the link's return to the first observation stored from the cut side (the cut instrument; for the
  planner, any instrument); for the flapping link the median and the largest over its returns;
- wall: from starting the nodes to the budget stored and everything measured or owed stored (the planner proposes on
  past the budget until stopped).

Needs root (network namespaces); DDS stays inside the namespaces the run creates.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

from benchmarks import netlab
from gryffin_ros.nodes.supervisor import signals_as_interrupt
from gryffin_ros.paths import share_path

CONFIG = share_path("examples") / "flow_reactor.yaml"
HANG_S = 600.0


def first_after(run: netlab.LabCampaign, when: float, side: str | None, timeout: float = 120.0) -> float | None:
    """Seconds from `when` to the first observation stored after it from instrument `side` (any with None)."""
    def found():
        times = [received for _, received, inst in run.observations()
                 if received > when and (side is None or inst.endswith("_" + side))]
        return min(times) if times else None
    netlab.wait_until(lambda: run.alive() and found() is not None, timeout)
    hit = found()
    return None if hit is None else hit - when


def owed_at(run: netlab.LabCampaign, when: float) -> set[str]:
    stored = {eid for eid, _, _ in run.observations()}
    return run.proposed_before(when) - stored


def cut_scenario(lab: netlab.NetLab, workdir: Path, args, discovery: str, host: str, seconds: float) -> dict:
    workdir.mkdir(parents=True)
    run = netlab.LabCampaign(lab, workdir, CONFIG, discovery, args.domain, seed=args.seed)
    begun = time.monotonic()
    run.start()
    if not netlab.wait_until(lambda: run.alive() and run.count() >= args.budget // 3, HANG_S):
        raise RuntimeError(f"the campaign did not start\n{run.log(run.planner)[-3000:]}")
    lab.cut(host)
    cut_at = time.time()
    time.sleep(seconds)  # the partition: its length is the experiment
    during = [inst for _, received, inst in run.observations() if received > cut_at + 1.0]
    lab.restore(host)
    restored = time.time()
    owed = owed_at(run, restored)
    side = host if host in run.instruments else None
    recover = first_after(run, restored, side)
    result = run.settle(args.budget, owed, HANG_S, settle_s=120.0)
    result.update({"scenario": f"{'instrument' if side else 'planner'} cut {seconds:g} s", "discovery": discovery,
                   "cut_s": seconds, "owed": len(owed), "recover_s": recover,
                   "stored_during_cut": len(during),
                   "stored_during_cut_from_cut_side": sum(i.endswith("_" + host) for i in during) if side else None,
                   "wall_s": time.monotonic() - begun})
    return result


def flap_scenario(lab: netlab.NetLab, workdir: Path, args, discovery: str, down: float, period: float) -> dict:
    workdir.mkdir(parents=True)
    run = netlab.LabCampaign(lab, workdir, CONFIG, discovery, args.domain, seed=args.seed)
    begun = time.monotonic()
    run.start()
    stop = threading.Event()
    returns: list[float] = []

    def flap():
        while not stop.wait(period - down):
            lab.cut("planner")
            stop.wait(down)
            lab.restore("planner")
            returns.append(time.time())
    flapper = threading.Thread(target=flap, daemon=True)
    flapper.start()
    try:
        if not netlab.wait_until(lambda: run.alive() and run.count() >= args.budget, HANG_S):
            raise RuntimeError(f"{run.count()} of {args.budget} stored\n{run.log(run.planner)[-3000:]}")
    finally:
        stop.set()
        flapper.join()
    observed = sorted(received for _, received, _ in run.observations())
    # recovery after each return: to the next stored observation (returns after the last one are not counted)
    gaps = [next(t for t in observed if t > back) - back for back in returns if observed and observed[-1] > back]
    result = run.settle(args.budget, (), HANG_S, settle_s=120.0)
    result.update({"scenario": f"planner link down {down:g} s in every {period:g} s", "discovery": discovery,
                   "returns": len(returns), "recover_s": statistics.median(gaps) if gaps else None,
                   "recover_max_s": max(gaps) if gaps else None, "owed": None, "wall_s": time.monotonic() - begun})
    return result


def fmt(value, digits: int = 1) -> str:
    if value is None:
        return "–"
    return f"{value:.{digits}f}" if isinstance(value, float) else str(value)


def table(results: list[dict]) -> str:
    lines = ["| scenario | discovery | lost | run twice | duplicate reports | owed at restore (all done) "
             "| recover, s | stored during cut (from cut side) | wall, s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        owed = "–" if r["owed"] is None else f"{r['owed']} ({'yes' if r['owed_not_done'] == 0 else 'NO'})"
        recover = fmt(r["recover_s"])
        if "recover_max_s" in r:
            recover = f"median {fmt(r['recover_s'])}, max {fmt(r['recover_max_s'])} ({r['returns']} returns)"
        during = "–"
        if "stored_during_cut" in r:
            during = str(r["stored_during_cut"])
            if r["stored_during_cut_from_cut_side"] is not None:
                during += f" ({r['stored_during_cut_from_cut_side']})"
        lines.append(f"| {r['scenario']} | {r['discovery']} | {r['lost']} | {r['run_twice']} | "
                     f"{r['duplicate_reports']} | {owed} | {recover} | {during} | {fmt(r['wall_s'], 0)} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--budget", type=int, default=40)
    parser.add_argument("--cuts", default="10,20,30", help="cut lengths in seconds, comma-separated")
    parser.add_argument("--discovery", default="static,subnet", help="static and/or subnet, comma-separated")
    parser.add_argument("--flap-s", default="1,5", help="down,period of the flapping link in seconds; '' for none")
    parser.add_argument("--hosts", default="instrument,planner", help="which link is cut: instrument and/or planner")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--domain", type=int, default=int(os.environ.get("ROS_DOMAIN_ID") or 57))
    parser.add_argument("--out", default="benchmarks/results/partitions")
    parser.add_argument("--workdir", help="keep each run's store and node logs here (default: a temporary folder)")
    args = parser.parse_args(argv)
    reason = netlab.unavailable()
    if reason is not None:
        print(f"cannot run: {reason}", file=sys.stderr)
        return 2
    cuts = [float(c) for c in args.cuts.split(",") if c]
    modes = [m for m in args.discovery.split(",") if m]
    hosts = [h for h in args.hosts.split(",") if h]
    plan = [(mode, host, cut) for mode in modes for host in hosts for cut in cuts]
    flap = [float(v) for v in args.flap_s.split(",")] if args.flap_s else None
    results = []
    with tempfile.TemporaryDirectory(prefix="partitions-") as scratch:
        tmp = args.workdir or scratch
        for k, (mode, host, cut) in enumerate(plan):
            with netlab.NetLab(["planner", "inst1", "inst2"]) as lab:
                target = "inst1" if host == "instrument" else "planner"
                results.append(cut_scenario(lab, Path(tmp) / f"run{k}", args, mode, target, cut))
            print(json.dumps(results[-1]), flush=True)
        if flap:
            for k, mode in enumerate(modes):
                with netlab.NetLab(["planner", "inst1", "inst2"]) as lab:
                    results.append(flap_scenario(lab, Path(tmp) / f"flap{k}", args, mode, *flap))
                print(json.dumps(results[-1]), flush=True)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    command = ".venv/bin/python -m benchmarks.partitions " + " ".join(argv if argv is not None else sys.argv[1:])
    out.with_suffix(".json").write_text(json.dumps({"command": command.strip(), "budget": args.budget,
                                                    "results": results}, indent=1) + "\n")
    setting = f"budget {args.budget}, batch 2, 0.5 s per experiment, two claiming instruments"
    out.with_suffix(".md").write_text(f"`{command.strip()}` as root ({setting})\n\n" + table(results) + "\n")
    print(table(results))
    bad = [r["scenario"] for r in results if r["lost"] or r["run_twice"] or r["owed_not_done"]
           or any(r["exit_codes"].values())]
    if bad:
        print(f"FAILED guarantees in: {bad}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    with signals_as_interrupt():  # the NetLab closes (its nodes stopped) on SIGTERM and SIGHUP too
        sys.exit(main())
