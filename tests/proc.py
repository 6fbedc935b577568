"""Processes as /proc sees them (not as logs say): a process's children, and whether a process is still running.

A process is identified by its pid and its start time (field 22 of /proc/PID/stat), so a pid reused by the system for
a new process is not mistaken for the old one; a zombie (state Z: exited, not yet reaped by its new parent) is not
running."""

from __future__ import annotations

import os
import time
from pathlib import Path

PROC = Path("/proc")


def _stat(pid: int) -> list[str] | None:
    try:
        text = (PROC / str(pid) / "stat").read_text()
    except (FileNotFoundError, ProcessLookupError, PermissionError):
        return None
    # "pid (comm) state ppid ...": comm may hold spaces and parentheses; the fields after the last ')' are fixed
    return [text[:text.index(" ")]] + text[text.rindex(")") + 2:].split()


def identity(pid: int) -> tuple[int, int] | None:
    """(pid, start time) of a process that exists now, or None."""
    fields = _stat(pid)
    return None if fields is None else (pid, int(fields[20]))


def children(pid: int) -> set[tuple[int, int]]:
    """The identities of the running processes whose parent is `pid`."""
    found = set()
    for entry in os.listdir(PROC):
        if not entry.isdigit():
            continue
        fields = _stat(int(entry))
        if fields is not None and fields[2] == str(pid) and fields[1] != "Z":
            found.add((int(entry), int(fields[20])))
    return found


def running(process: tuple[int, int]) -> bool:
    """Whether the process with this identity still runs (a zombie does not)."""
    fields = _stat(process[0])
    return fields is not None and int(fields[20]) == process[1] and fields[1] != "Z"


def wait_gone(processes: set[tuple[int, int]], timeout: float) -> set[tuple[int, int]]:
    """Wait until none of `processes` runs, at most `timeout` seconds; those still running then."""
    deadline = time.monotonic() + timeout
    while True:
        left = {p for p in processes if running(p)}
        if not left or time.monotonic() > deadline:
            return left
        time.sleep(0.05)


def command_line(process: tuple[int, int]) -> str:
    try:
        return (PROC / str(process[0]) / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return "?"


def session(pid: int) -> int | None:
    """The session id of a running process."""
    fields = _stat(pid)
    return None if fields is None else int(fields[4])


def open_files(pid: int) -> dict[int, str]:
    """What each open file descriptor of a process points to (a path, `pipe:[inode]`, `socket:[inode]`); empty for
    a process that is gone."""
    fd_dir = PROC / str(pid) / "fd"
    try:
        entries = os.listdir(fd_dir)
    except OSError:
        return {}
    found = {}
    for entry in entries:
        try:
            found[int(entry)] = os.readlink(fd_dir / entry)
        except OSError:  # closed meanwhile
            continue
    return found


def pipe_inodes(pid: int) -> set[str]:
    """The pipes a process holds open beyond its standard input, output and error."""
    return {target for fd, target in open_files(pid).items() if fd > 2 and target.startswith("pipe:[")}
