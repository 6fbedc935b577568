"""The supervisor's mechanics with small stand-in children (no DDS; the real nodes under `gryffin-ros campaign` are
in tests/nodes/test_supervision.py): a child stops when its supervisor is gone, SIGKILL included; stopping escalates
from SIGINT to SIGTERM to SIGKILL and says how each child ended; SIGTERM and SIGHUP stop a supervisor as Ctrl-C does.
Processes are checked in /proc."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap

import pytest

from gryffin_ros.nodes.supervisor import LIFELINE_ENV, Supervisor
from tests import proc

# Deadlines only catch hangs (a child here starts in well under a second); a passing test never waits for one.
HANG_S = 60.0

# a child that stops cleanly on SIGINT or when its supervisor is gone; says "ready" once it is
CHILD = textwrap.dedent("""
    import signal, sys, threading
    from gryffin_ros.nodes.supervisor import watch_lifeline
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    ignore = set(sys.argv[1:])
    for name in ignore - {"LIFELINE"}:
        signal.signal(getattr(signal, name), signal.SIG_IGN)
    watched = watch_lifeline(stop.set if "LIFELINE" not in ignore else (lambda: None), grace_s=1.0)
    print("ready", watched, flush=True)
    stop.wait()
""")

# a supervisor of one CHILD (arguments: what the child ignores), inside signals_as_interrupt as the CLI runs;
# prints the child's pid, then how it ended
SUPERVISOR = textwrap.dedent("""
    import subprocess, sys, time
    from gryffin_ros.nodes.supervisor import Interrupted, Supervisor, signals_as_interrupt
    with signals_as_interrupt():
        supervisor = Supervisor(stop_timeout_s=2.0, kill_timeout_s=2.0)
        try:
            child = supervisor.start("child", [sys.executable, "-c", sys.argv[1], *sys.argv[2:]],
                                     stdout=subprocess.PIPE, text=True)
            child.stdout.readline()
            print(child.pid, flush=True)
            time.sleep(600)
        except Interrupted as exc:
            code = exc.exit_code
        finally:
            for end in supervisor.stop():
                print(end, flush=True)
    sys.exit(code)
""")


def start_supervisor(*ignore: str) -> tuple[subprocess.Popen, tuple[int, int]]:
    supervisor = subprocess.Popen([sys.executable, "-c", SUPERVISOR, CHILD, *ignore], stdout=subprocess.PIPE,
                                  text=True)
    child = proc.identity(int(supervisor.stdout.readline()))
    assert child is not None and proc.running(child)
    return supervisor, child


def start_child(supervisor: Supervisor, *ignore: str) -> subprocess.Popen:
    child = supervisor.start("child", [sys.executable, "-c", CHILD, *ignore], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().split() == ["ready", "True"]
    return child


@pytest.mark.parametrize("ignore", [(), ("LIFELINE",)], ids=["clean", "stuck"])
def test_a_child_stops_when_its_supervisor_is_killed(ignore):
    supervisor, child = start_supervisor(*ignore)
    supervisor.kill()  # SIGKILL: nothing of the supervisor runs
    supervisor.wait()
    # a stuck child (its shutdown never ends) leaves after the grace period all the same
    assert not proc.wait_gone({child}, HANG_S), proc.command_line(child)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_stop_signal_to_the_supervisor_stops_its_child_and_is_reported(sig):
    supervisor, child = start_supervisor()
    supervisor.send_signal(sig)
    output, _ = supervisor.communicate(timeout=HANG_S)
    assert supervisor.returncode == 128 + sig, output
    assert "child (pid" in output and "stopped by SIGINT, exit code 0" in output
    assert not proc.running(child)


def test_stopping_escalates_to_sigterm_then_sigkill_and_says_so():
    supervisor = Supervisor(stop_timeout_s=0.5, kill_timeout_s=0.5)
    clean = start_child(supervisor)
    deaf = start_child(supervisor, "SIGINT")
    stubborn = start_child(supervisor, "SIGINT", "SIGTERM")
    ended = {end.pid: end for end in supervisor.stop()}
    assert (ended[clean.pid].how, ended[clean.pid].returncode, ended[clean.pid].clean) == (
        "stopped by SIGINT", 0, True)
    assert (ended[deaf.pid].how, ended[deaf.pid].returncode) == ("stopped by SIGTERM", -signal.SIGTERM)
    assert (ended[stubborn.pid].how, ended[stubborn.pid].returncode) == ("killed", -signal.SIGKILL)
    assert "signal SIGKILL" in str(ended[stubborn.pid]) and not ended[stubborn.pid].clean
    assert supervisor.stop() == []  # nothing left to stop


def test_children_run_in_a_session_of_their_own_and_hold_only_their_own_lifeline():
    with Supervisor() as supervisor:
        first = start_child(supervisor)
        second = start_child(supervisor)
        for child in (first, second):
            assert proc.session(child.pid) == child.pid  # a terminal's Ctrl-C goes to the supervisor only
        # the second child did not inherit the first one's write end (else the first would outlive us)
        assert proc.pipe_inodes(second.pid) & proc.pipe_inodes(first.pid) == set()


def test_a_wrong_lifeline_variable_is_said_and_ignored():
    result = subprocess.run([sys.executable, "-c", CHILD.replace("stop.wait()", "")], capture_output=True, text=True,
                            env={**__import__("os").environ, LIFELINE_ENV: "99"}, timeout=HANG_S)
    assert result.stdout.split() == ["ready", "False"]
    assert f"{LIFELINE_ENV}='99' names no open pipe" in result.stderr
