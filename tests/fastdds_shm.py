"""Fast DDS shared memory in /dev/shm, judged from the files themselves rather than from the wording of `fastdds shm
clean` (a third-party tool's output, which changes between Fast DDS releases).

Every Fast DDS port and segment has a lock file (`fastrtps_port<N>_el|_sl`, `fastrtps_<16 chars>_el|_sl`) that its
owner holds locked while it lives; one that can be locked belongs to a dead process: a zombie. This is the test that
`fastdds shm clean` applies before it removes a port's or segment's files.
"""

from __future__ import annotations

import fcntl
import os
import re
import subprocess
import sys
from pathlib import Path

from tests import proc

SHM_DIR = Path("/dev/shm")
LOCK_FILE = re.compile(r"^fastrtps_(port\d{1,5}|[0-9a-z]{16})_(el|sl)$")


def lock_files() -> set[str]:
    """Names of the Fast DDS lock files in /dev/shm now."""
    try:
        names = os.listdir(SHM_DIR)
    except FileNotFoundError:
        return set()
    return {name for name in names if LOCK_FILE.match(name)}


def zombies(names: set[str] | None = None) -> set[str]:
    """The lock files among `names` (default: all of them) whose owner is gone."""
    dead = set()
    for name in lock_files() if names is None else names:
        try:
            fd = os.open(SHM_DIR / name, os.O_RDONLY)
        except OSError:  # removed meanwhile, or another user's
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            continue  # held: its owner is alive
        else:
            dead.add(name)  # closing the descriptor releases the lock again at once
        finally:
            os.close(fd)
    return dead


def clean() -> None:
    """Remove the files of dead participants with Fast DDS's own tool (its exit status is checked, its text is not)."""
    tool = Path(sys.executable).with_name("fastdds")
    subprocess.run([str(tool), "shm", "clean"], capture_output=True, check=True, timeout=180)


def held_by(pid: int) -> set[str]:
    """The Fast DDS lock files a running process holds open now (its ports and segments): what it leaves behind if
    it dies without cleaning up. Judging only these keeps a check to its own test's processes, whatever other
    DDS processes (a parallel test worker's) do meanwhile."""
    targets = (Path(target) for target in proc.open_files(pid).values())
    return {t.name for t in targets if t.parent == SHM_DIR and LOCK_FILE.match(t.name)}


# RTPS well-known ports (the Fast DDS shared-memory transport uses the same numbers): PB + DG * domain + offset
PORT_BASE, DOMAIN_GAIN = 7400, 250


def of_domain(names: set[str], domain: int) -> set[str]:
    """Of `names`, the participants' own segments and the ports of `domain`'s range. Other ports a node holds (a
    shared port below the domain ranges, 7001/7003 as seen here) are shared with the processes of other domains, a
    parallel test worker's among them, and may be left by them: not this test's to judge."""
    low = PORT_BASE + DOMAIN_GAIN * domain
    own = set()
    for name in names:
        match = LOCK_FILE.match(name)
        if not match:
            continue
        key = match.group(1)
        if not key.startswith("port") or low <= int(key[4:]) < low + DOMAIN_GAIN:
            own.add(name)
    return own
