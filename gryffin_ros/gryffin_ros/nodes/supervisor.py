"""Node processes owned by the process that starts them: never orphaned, stopped in order, their end reported.

`Supervisor` (the starting side: `gryffin-ros campaign`, benchmarks, tests) starts each node

- in a session (so a process group) of its own, so a terminal's Ctrl-C or a service manager's signal reaches the
  supervisor alone, which then stops its nodes once each, in order (SIGINT, the nodes' clean shutdown; SIGTERM
  after `stop_timeout_s`; SIGKILL after `kill_timeout_s` more), waits for them and says how each one ended;
- holding the read end of a pipe, its *lifeline*, whose write end only the supervisor holds. However the supervisor
  ends, SIGKILL included, the kernel closes that end; the node (`watch_lifeline`, called by `runner.run`) reads end
  of file, shuts down as on SIGINT and exits regardless after `ORPHAN_GRACE_S`.

Why a pipe and not Linux's `PR_SET_PDEATHSIG`: the death signal follows the *thread* that forked the child (a node
started from a helper thread would be killed when that thread ends), it has to be set between fork and exec
(`preexec_fn`, unsafe in a process with threads, as the dashboard's server and the tests' executors are), it is
Linux-only, and it misses a parent that died before the child set it. A pipe closes when the process is gone, from
any thread, on any POSIX system, and passes through `ip netns exec`.

`signals_as_interrupt` makes SIGTERM and SIGHUP (what systemd, a CI runner, a closed terminal send) stop the
supervisor the way Ctrl-C does: a `KeyboardInterrupt` (`Interrupted`, with the signal) in the main thread, so the
`finally` blocks that stop the nodes run.

Nothing here imports rclpy.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

LIFELINE_ENV = "GRYFFIN_ROS_LIFELINE"
# after its supervisor is gone a node has this long to shut down cleanly (finish storing what arrived, stop a
# running optimization at its next checkpoint), then it exits regardless
ORPHAN_GRACE_S = 5.0
# exit code of a node that had to leave without its clean shutdown after its supervisor was gone
ORPHAN_EXIT_CODE = 3
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Interrupted(KeyboardInterrupt):
    """The process was asked to stop by a signal (SIGINT, SIGTERM or SIGHUP)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum

    @property
    def exit_code(self) -> int:
        """The shell's convention for a process ended by this signal: 128 + its number (130 for Ctrl-C)."""
        return 128 + self.signum


@contextmanager
def signals_as_interrupt() -> Iterator[None]:
    """While the block runs (in the main thread), SIGINT, SIGTERM and SIGHUP raise `Interrupted` once; a later one
    is only noted, so the stopping that the first one started runs to its end (it is bounded)."""
    raised: list[int] = []

    def handler(signum: int, _frame: Any) -> None:
        if raised:
            print(f"{signal.Signals(signum).name}: already stopping", file=sys.stderr, flush=True)
            return
        raised.append(signum)
        raise Interrupted(signum)

    previous = {sig: signal.signal(sig, handler) for sig in STOP_SIGNALS}
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


@dataclass(frozen=True)
class Ended:
    """How one supervised process ended."""

    name: str
    pid: int
    returncode: int
    how: str  # "had exited", "stopped by SIGINT", "stopped by SIGTERM", "killed"

    def __str__(self) -> str:
        code = (f"signal {signal.Signals(-self.returncode).name}" if self.returncode < 0
                else f"exit code {self.returncode}")
        return f"{self.name} (pid {self.pid}): {self.how}, {code}"

    @property
    def clean(self) -> bool:
        return self.how in ("had exited", "stopped by SIGINT") and self.returncode == 0


class Supervisor:
    """Starts node processes and owns them (module doc). Use as a context manager: leaving the block stops them and
    says on stderr how each ended; or call `stop`, which returns that."""

    def __init__(self, stop_timeout_s: float = 10.0, kill_timeout_s: float = 5.0) -> None:
        self.stop_timeout_s = stop_timeout_s
        self.kill_timeout_s = kill_timeout_s
        self._children: list[tuple[str, subprocess.Popen, int]] = []  # name, process, lifeline write end
        self._lock = threading.Lock()

    def start(self, name: str, argv: Sequence[str], env: Mapping[str, str] | None = None,
              **popen: Any) -> subprocess.Popen:
        """Start `argv` as the supervised process `name` (keyword arguments go to `subprocess.Popen`; a session,
        hence a process group, of its own unless `start_new_session` or `process_group` says otherwise)."""
        read_end, write_end = os.pipe()  # both non-inheritable: only pass_fds hands the read end to the child
        child_env = dict(os.environ if env is None else env)
        child_env[LIFELINE_ENV] = str(read_end)
        if "process_group" not in popen:  # Python 3.11+; a session of its own works from 3.10
            popen.setdefault("start_new_session", True)
        popen["pass_fds"] = tuple(popen.get("pass_fds", ())) + (read_end,)
        # (signals are not blocked around Popen: a child inherits the signal mask. A signal landing between Popen
        # and the registration leaves that child unknown here, yet not orphaned: its lifeline closes with us.)
        try:
            with self._lock:
                process = subprocess.Popen(list(argv), env=child_env, **popen)
                self._children.append((name, process, write_end))
        except BaseException:
            os.close(write_end)
            raise
        finally:
            os.close(read_end)
        return process

    @property
    def processes(self) -> list[subprocess.Popen]:
        with self._lock:
            return [process for _, process, _ in self._children]

    def stop(self) -> list[Ended]:
        """Stop every process still running (SIGINT to all, then SIGTERM to those still running after
        `stop_timeout_s`, then SIGKILL after `kill_timeout_s`), wait for each, close the lifelines; how each one
        ended, in start order. A stop signal arriving meanwhile is held until the end (it is bounded)."""
        blocked = _block_stop_signals()
        try:
            return self._stop()
        finally:
            _unblock(blocked)

    def _stop(self) -> list[Ended]:
        with self._lock:
            children, self._children = self._children, []
        how: dict[int, str] = {}
        for _, process, _ in children:
            if process.poll() is None:
                _signal(process, signal.SIGINT)
                how[process.pid] = "stopped by SIGINT"
            else:
                how[process.pid] = "had exited"
        for sig, timeout, label in ((signal.SIGTERM, self.stop_timeout_s, "stopped by SIGTERM"),
                                    (signal.SIGKILL, self.kill_timeout_s, "killed")):
            deadline = time.monotonic() + timeout
            for _, process, _ in children:
                try:
                    process.wait(timeout=max(0.0, deadline - time.monotonic()))
                except subprocess.TimeoutExpired:
                    pass
            for _, process, _ in children:
                if process.poll() is None:
                    _signal(process, sig)
                    how[process.pid] = label
        ended = []
        for name, process, write_end in children:
            process.wait()
            os.close(write_end)
            ended.append(Ended(name, process.pid, process.returncode, how[process.pid]))
        return ended

    def __enter__(self) -> Supervisor:
        return self

    def __exit__(self, *exc: object) -> None:
        for end in self.stop():  # said on stderr: how each process this block started ended
            print(end, file=sys.stderr, flush=True)


def _signal(process: subprocess.Popen, sig: int) -> None:
    try:
        process.send_signal(sig)
    except ProcessLookupError:  # ended meanwhile
        pass


def _block_stop_signals() -> set[int] | None:
    if threading.current_thread() is not threading.main_thread():
        return None  # signals are handled in the main thread only
    return signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)


def _unblock(previous: set[int] | None) -> None:
    if previous is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def watch_lifeline(on_break: Callable[[], None], grace_s: float = ORPHAN_GRACE_S) -> bool:
    """In a node started by a `Supervisor`: when the supervisor is gone, call `on_break` (begin the clean shutdown)
    and exit the process regardless `grace_s` later. Returns whether there is a lifeline to watch."""
    value = os.environ.pop(LIFELINE_ENV, None)
    if not value:
        return False
    try:
        fd = int(value)
        os.fstat(fd)
    except (ValueError, OSError):
        print(f"{LIFELINE_ENV}={value!r} names no open pipe; this node will not notice its supervisor's end",
              file=sys.stderr, flush=True)
        return False

    def watch() -> None:
        while True:
            try:
                if not os.read(fd, 1):  # end of file: the supervisor's end is closed
                    break
            except InterruptedError:
                continue
            except OSError:
                break
        print("supervisor gone: shutting down", file=sys.stderr, flush=True)
        on_break()
        time.sleep(grace_s)
        print(f"supervisor gone: not shut down within {grace_s:.0f} s, exiting", file=sys.stderr, flush=True)
        os._exit(ORPHAN_EXIT_CODE)

    threading.Thread(target=watch, name="gryffin_ros_lifeline", daemon=True).start()
    return True
