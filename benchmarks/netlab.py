"""Separate hosts on one machine: Linux network namespaces joined by a switch, for tests and benchmarks of a lab whose
planner and instruments run on different computers.

A `NetLab` creates one namespace per host and one for the switch: the switch holds a bridge, each host is joined to
it by a veth pair (`eth0` inside the host, `<host>` on the bridge) with an address of a private subnet, and the hosts
have their own loopback. Nothing is connected to the machine's own interfaces, so every packet — DDS discovery
multicast included — stays inside namespaces the lab created. `cut(host)` takes a host's link down (on the switch's
side, as a pulled cable: the host's `eth0` loses its carrier), `restore(host)` brings it back.

Processes are started in a host with `start(host, argv, env=...)`; `dds_environment(host, discovery)` is the
environment the README tells a lab to give each computer, nothing more. (Fast DDS does not take namespaces on one
machine for one host: no data goes over shared memory between them, so a cut link stops every byte: seen with a
talker/listener pair, and tests/hosts checks that a cut instrument's results stop arriving during its cut.)

Everything is removed on exit, also when a test fails: the processes started in the lab are killed, the namespaces
deleted (which deletes their interfaces). Labs left behind by a killed run (their creator's pid is gone) are removed
when the next one starts. Needs root (CAP_NET_ADMIN) and `ip`; `unavailable()` says why a lab cannot be made here.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from gryffin_ros.nodes.rosenv import profile_path
from gryffin_ros.nodes.supervisor import Supervisor

PREFIX = "grlab"
SUBNET = "10.213.7"  # /24 inside the lab only; host k gets SUBNET.(k + 1)


def _ip(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run(["ip", *args], check=check, capture_output=True, text=True, timeout=30)


def unavailable() -> str | None:
    """Why network namespaces cannot be made here (None when they can)."""
    if shutil.which("ip") is None:
        return "the 'ip' command (iproute2) is not installed"
    if os.geteuid() != 0:
        return "creating network namespaces needs root (CAP_NET_ADMIN); CI runs as root"
    probe = f"{PREFIX}{os.getpid()}probe"
    made = _ip("netns", "add", probe, check=False)
    if made.returncode != 0:
        return f"'ip netns add' is not permitted here: {made.stderr.strip()}"
    _ip("netns", "del", probe, check=False)
    return None


def _remove_stale() -> None:
    """Remove labs whose creating process is gone (a run killed before its cleanup)."""
    listing = _ip("netns", "list", check=False).stdout.split("\n")
    for line in listing:
        name = line.split(" ")[0]
        if not name.startswith(PREFIX):
            continue
        pid = name[len(PREFIX):].split("-")[0]
        if pid.isdigit() and not Path(f"/proc/{pid}").exists():
            _ip("netns", "del", name, check=False)


class NetLab:
    """Hosts `names` (short names, at most 10 characters) on one switch. Use as a context manager."""

    def __init__(self, names: Sequence[str]):
        if len(set(names)) != len(names) or any(not n.isalnum() or len(n) > 10 for n in names):
            raise ValueError(f"host names must be distinct, alphanumeric, at most 10 characters: {list(names)}")
        self.names = list(names)
        self.tag = f"{PREFIX}{os.getpid()}-{id(self) % 10000}"
        self.switch = f"{self.tag}-sw"
        self.address = {name: f"{SUBNET}.{k + 1}" for k, name in enumerate(self.names)}
        # every process started in a host is owned by a supervisor: stopped when the lab closes, and gone by itself
        # when the process holding the lab is killed (gryffin_ros.nodes.supervisor)
        self.supervisor = Supervisor(stop_timeout_s=10.0, kill_timeout_s=5.0)
        self._made: list[str] = []

    def namespace(self, host: str) -> str:
        return f"{self.tag}-{host}"

    # ---- lifetime ------------------------------------------------------------------------------------------
    def __enter__(self) -> NetLab:
        _remove_stale()
        try:
            self._create()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def _create(self) -> None:
        _ip("netns", "add", self.switch)
        self._made.append(self.switch)
        _ip("-n", self.switch, "link", "add", "name", "br0", "type", "bridge")
        _ip("-n", self.switch, "link", "set", "br0", "up")
        _ip("-n", self.switch, "link", "set", "lo", "up")
        for host in self.names:
            ns = self.namespace(host)
            _ip("netns", "add", ns)
            self._made.append(ns)
            _ip("-n", self.switch, "link", "add", "name", host, "type", "veth", "peer", "name", "eth0", "netns", ns)
            _ip("-n", self.switch, "link", "set", "dev", host, "master", "br0")
            _ip("-n", self.switch, "link", "set", "dev", host, "up")
            _ip("-n", ns, "link", "set", "lo", "up")
            _ip("-n", ns, "addr", "add", f"{self.address[host]}/24", "dev", "eth0")
            _ip("-n", ns, "link", "set", "eth0", "up")
            # multicast (DDS discovery with ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET) goes out of eth0, the only route
            _ip("-n", ns, "route", "add", "224.0.0.0/4", "dev", "eth0")

    @property
    def processes(self) -> list[subprocess.Popen]:
        return self.supervisor.processes

    def close(self) -> None:
        for end in self.supervisor.stop():  # what is still running (a campaign stops its nodes itself, in order)
            if end.how != "had exited":
                print(end, file=sys.stderr, flush=True)
        for ns in reversed(self._made):
            _ip("netns", "del", ns, check=False)
        self._made.clear()

    # ---- the network ---------------------------------------------------------------------------------------
    def cut(self, host: str) -> None:
        """Pull the host's cable: its port on the switch goes down."""
        _ip("-n", self.switch, "link", "set", "dev", host, "down")

    def restore(self, host: str) -> None:
        _ip("-n", self.switch, "link", "set", "dev", host, "up")

    def interfaces(self, host: str | None = None) -> list[str]:
        """Names of the interfaces in a host's namespace (the switch's with None)."""
        ns = self.switch if host is None else self.namespace(host)
        out = _ip("-n", ns, "-o", "link", "show").stdout
        return [line.split(":")[1].strip().split("@")[0] for line in out.splitlines() if line.strip()]

    # ---- processes -----------------------------------------------------------------------------------------
    def dds_environment(self, host: str, discovery: str, domain_id: int,
                        base: Mapping[str, str] | None = None) -> dict[str, str]:
        """What a lab computer exports (README, "Across machines"): one domain for the campaign, and either subnet
        discovery (`discovery="subnet"`) or static peers — the other hosts' addresses — on top of local discovery
        (`"static"`)."""
        env = dict(os.environ if base is None else base)
        env.pop("ROS_STATIC_PEERS", None)
        env.update({"ROS_DOMAIN_ID": str(domain_id), "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp",
                    "FASTRTPS_DEFAULT_PROFILES_FILE": profile_path()})
        if discovery == "subnet":
            env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "SUBNET"
        elif discovery == "static":
            env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
            env["ROS_STATIC_PEERS"] = ";".join(a for h, a in self.address.items() if h != host)
        else:
            raise ValueError(f"discovery must be 'subnet' or 'static', got {discovery!r}")
        return env

    def start(self, host: str, argv: Sequence[str], env: Mapping[str, str], **popen) -> subprocess.Popen:
        """Start a process in the host's namespace (its own process group, stopped when the lab closes)."""
        return self.supervisor.start(host, ["ip", "netns", "exec", self.namespace(host), *argv], env, **popen)


def wait_until(condition, timeout: float, interval: float = 0.05) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(interval)
    return condition()


class LabCampaign:
    """A flow-reactor campaign across a NetLab: the planner node on host `planner`, a claiming flow-reactor emulator
    node (an instrument) on each of `instruments`, everyone with `discovery` ("static" or "subnet"). What happened is
    read from the outside: the campaign store (SQLite, read-only while the planner writes) and the nodes' logs."""

    def __init__(self, lab: NetLab, workdir: Path, config: Path, discovery: str, domain_id: int,
                 planner: str = "planner", instruments: Sequence[str] = ("inst1", "inst2"),
                 experiment_time_s: float = 0.5, batch_size: int = 2, seed: int = 0, python: str | None = None):
        self.lab, self.workdir, self.config = lab, Path(workdir), Path(config)
        self.discovery, self.domain_id = discovery, domain_id
        self.planner, self.instruments = planner, list(instruments)
        self.experiment_time_s, self.batch_size, self.seed = experiment_time_s, batch_size, seed
        self.python = python or sys.executable
        self.storage = self.workdir / "campaign.sqlite"
        self.logs: dict[str, Path] = {}
        self.processes: dict[str, subprocess.Popen] = {}

    def _start(self, host: str, argv: list[str]) -> None:
        env = self.lab.dds_environment(host, self.discovery, self.domain_id)
        env["ROS_LOG_DIR"] = str(self.workdir / "ros_logs")
        env["PYTHONUNBUFFERED"] = "1"
        self.logs[host] = self.workdir / f"{host}.log"
        with open(self.logs[host], "w") as log:
            self.processes[host] = self.lab.start(host, [self.python, "-m", *argv], env, stdout=log,
                                                  stderr=subprocess.STDOUT)

    def start(self, timeout: float = 120.0) -> None:
        self._start(self.planner, ["gryffin_ros.nodes.planner_node", "--ros-args", "-p", f"config:={self.config}",
                                   "-p", f"storage:={self.storage}", "-p", f"seed:={self.seed}",
                                   "-p", f"batch_size:={self.batch_size}", "-p", "auto_propose:=true"])
        for k, host in enumerate(self.instruments):
            self._start(host, ["gryffin_ros.nodes.emulator_node", "flow_reactor", "--ros-args",
                               "-r", f"__node:=flow_reactor_{host}", "-p", "claim:=true",
                               "-p", f"experiment_time_s:={self.experiment_time_s}", "-p", f"seed:={self.seed + k}"])
        if not wait_until(lambda: self.alive() and ": active" in self.log(self.planner), timeout):
            raise RuntimeError(f"the planner did not come up:\n{self.log(self.planner)[-3000:]}")

    def alive(self) -> bool:
        dead = {h: p.returncode for h, p in self.processes.items() if p.poll() is not None}
        if dead:
            raise RuntimeError(f"exited: {dead}\n" + "\n".join(f"--- {h}\n{self.log(h)[-3000:]}" for h in dead))
        return True

    def log(self, host: str) -> str:
        return self.logs[host].read_text(errors="replace") if host in self.logs else ""

    def stop(self, timeout: float = 60.0) -> dict[str, int]:
        """SIGINT to every node (instruments first), as a lab would stop them; returns the exit codes."""
        codes = {}
        for host in [*self.instruments, self.planner]:
            process = self.processes[host]
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGINT)
            try:
                codes[host] = process.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                codes[host] = process.wait()
        return codes

    def settle(self, budget: int, owed: Iterable[str] = (), timeout: float = 180.0, settle_s: float = 60.0
               ) -> dict:
        """Run to `budget` stored observations; then wait (up to `settle_s`) until every experiment measured by then
        and every one of `owed` is stored (a report may still be on its way: instruments send again until
        acknowledged); stop the nodes. Returns `accounting` of what was measured by then, with owed_not_done (of
        `owed`, not stored), settled (everything was stored in time) and the nodes' exit_codes."""
        if not wait_until(lambda: self.alive() and self.count() >= budget, timeout):
            raise RuntimeError(f"{self.count()} of {budget} experiments stored after {timeout:.0f} s\n"
                               f"{self.log(self.planner)[-3000:]}")
        measured, owed = self.snapshot_measured(), set(owed)
        stored = lambda: {eid for eid, _, _ in self.observations()}  # noqa: E731
        settled = wait_until(lambda: self.alive() and measured | owed <= stored(), settle_s)
        result = self.accounting(measured)
        result.update(owed_not_done=len(owed - stored()), settled=settled, exit_codes=self.stop())
        return result

    # ---- what happened -------------------------------------------------------------------------------------
    def _query(self, sql: str, args: tuple = ()) -> list[tuple]:
        if not self.storage.exists():
            return []
        db = sqlite3.connect(f"file:{self.storage}?mode=ro", uri=True, timeout=30)
        try:
            return db.execute(sql, args).fetchall()
        except sqlite3.OperationalError:  # the planner has not created its tables yet
            return []
        finally:
            db.close()

    def observations(self) -> list[tuple[str, float, str]]:
        """(experiment_id, received, instrument) of every stored observation, in arrival order."""
        rows = self._query("SELECT experiment_id, received, meta FROM observations ORDER BY seq")
        return [(eid, received, json.loads(meta).get("instrument", "")) for eid, received, meta in rows]

    def count(self) -> int:
        rows = self._query("SELECT COUNT(*) FROM observations")
        return rows[0][0] if rows else 0

    def proposed_before(self, when: float) -> set[str]:
        return {eid for (eid,) in self._query("SELECT experiment_id FROM proposals WHERE created < ?", (when,))}

    def rejections(self) -> list[str]:
        return [reason for (reason,) in self._query("SELECT reason FROM rejections ORDER BY seq")]

    def measured(self, host: str) -> list[str]:
        """Experiment ids the instrument on `host` ran, from its log ("measuring <id>")."""
        return re.findall(r"measuring ([0-9a-f-]{36})", self.log(host))

    def snapshot_measured(self) -> set[str]:
        """The experiments measured so far, by any instrument."""
        return {eid for host in self.instruments for eid in self.measured(host)}

    def accounting(self, measured: set[str] | None = None) -> dict[str, int]:
        """Experiments stored; run twice (by two instruments, or twice by one); lost: of `measured` (default: every
        experiment any instrument ran), those not stored; reports sent again that the planner already had; other
        refused reports."""
        runs = [eid for host in self.instruments for eid in self.measured(host)]
        stored = {eid for eid, _, _ in self.observations()}
        rejections = self.rejections()
        return {"stored": len(stored), "run_twice": len(runs) - len(set(runs)),
                "lost": len((set(runs) if measured is None else measured) - stored),
                "duplicate_reports": sum("already reported" in r for r in rejections),
                "other_rejections": sum("already reported" not in r for r in rejections)}
