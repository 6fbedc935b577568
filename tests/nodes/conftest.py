"""Real ROS 2: the planner node runs in its own process; the test process talks to it over DDS on loopback.

Every test run uses its own ROS_DOMAIN_ID (set by `make test`, else derived from the pid) and
ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST with the fast-discovery profile.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import pytest
import yaml

from gryffin_ros.nodes.rosenv import ros_environment
from gryffin_ros.nodes.supervisor import Supervisor

os.environ.update(ros_environment())  # before rclpy is initialized in this process

import rclpy  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.node import Node  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from gryffin_ros.nodes.qos import EVENTS_QOS, LATCHED_QOS, OBSERVATIONS_QOS  # noqa: E402

PLUGIN_PATH = Path(__file__).resolve().parents[1] / "plugin_package"
# Deadlines only catch hangs. Each is many times what its step takes on a busy 2-core machine (a node starts in
# about 5 s there, an ask takes about a second, discovery and an answer well under one), so a slow machine waits
# longer but never fails a test that a fast one passes; a passing test never waits for a deadline.
HANG_S = 180.0
# a query (a request that changes nothing) not answered this long after is sent again (answers take well under a
# second there)
QUERY_RESEND_S = 5.0
FLOW_CONFIG = {
    "name": "flow_test",
    "parameters": [{"name": "F_C", "type": "continuous", "low": 0.0, "high": 200.0},
                   {"name": "F_S", "type": "continuous", "low": 0.0, "high": 200.0},
                   {"name": "T", "type": "continuous", "low": 100.0, "high": 150.0}],
    "objectives": [{"name": "X1_X2", "goal": "max"}],
    "constraints": [{"plugin": "flow_reactor"}],
}


def flow_feasible(p: dict) -> bool:
    return 30 < p["F_C"] + p["F_S"] < 310 and p["F_C"] < 2 * p["F_S"] and p["F_S"] < 2 * p["F_C"]


def query(client, request):
    """The answer to a request that changes nothing, sent again while the answer does not come: a service is
    "available" as soon as this side matched the node, but the node may not have matched this side's answer reader
    yet, and then drops its answer (CI lost a lifecycle answer that way: a 180 s hang)."""
    deadline = time.monotonic() + HANG_S
    while True:
        assert client.wait_for_service(timeout_sec=HANG_S), f"{client.srv_name} not available"
        future = client.call_async(request)
        resend_at = time.monotonic() + QUERY_RESEND_S
        while not future.done() and time.monotonic() < resend_at:
            time.sleep(0.01)
        if future.done():
            return future.result()
        client.remove_pending_request(future)
        assert time.monotonic() < deadline, f"no answer from {client.srv_name} in {HANG_S:.0f} s of resending"


class Client(Node):
    """The lab side over the JSON bridge (~/json/...): publishes observations, records events/status/proposals,
    calls the services."""

    def __init__(self) -> None:
        super().__init__("test_lab_client")
        self.events: list[dict] = []
        self.proposals: list[dict] = []
        self.statuses: list[dict] = []
        self.lock = threading.Lock()
        self.publisher = self.create_publisher(String, "/gryffin_planner/json/observations", OBSERVATIONS_QOS)
        self.create_subscription(String, "/gryffin_planner/json/events", self._record(self.events), EVENTS_QOS)
        self.create_subscription(String, "/gryffin_planner/json/proposals", self._record(self.proposals), LATCHED_QOS)
        self.create_subscription(String, "/gryffin_planner/json/status", self._record(self.statuses), LATCHED_QOS)
        self.recommend_client = self.create_client(Trigger, "/gryffin_planner/json/recommend")
        self.status_client = self.create_client(Trigger, "/gryffin_planner/json/get_status")

    def _record(self, sink: list):
        def callback(msg: String) -> None:
            with self.lock:
                sink.append(json.loads(msg.data))
        return callback

    def call(self, client, timeout: float = HANG_S) -> Trigger.Response:
        assert client.wait_for_service(timeout_sec=timeout), f"service {client.srv_name} not available"
        future = client.call_async(Trigger.Request())
        deadline = time.monotonic() + timeout
        while not future.done():
            assert time.monotonic() < deadline, f"no answer from {client.srv_name}"
            time.sleep(0.01)
        return future.result()

    def status(self) -> dict:
        return json.loads(query(self.status_client, Trigger.Request()).message)

    def recommend(self) -> Trigger.Response:
        return self.call(self.recommend_client)

    def wait_matched(self, timeout: float = HANG_S) -> None:
        deadline = time.monotonic() + timeout
        while self.publisher.get_subscription_count() == 0:
            assert time.monotonic() < deadline, "planner's observation subscription never matched"
            time.sleep(0.02)

    def publish(self, payload) -> None:
        self.publisher.publish(String(data=payload if isinstance(payload, str) else json.dumps(payload)))

    def wait_events(self, count: int, timeout: float = HANG_S) -> list[dict]:
        deadline = time.monotonic() + timeout
        while True:
            with self.lock:
                observed = [e for e in self.events if e["type"].startswith("observation_")]
            if len(observed) >= count:
                return observed
            assert time.monotonic() < deadline, f"expected {count} observation events, got {observed}"
            time.sleep(0.02)

    def wait_proposals(self, count: int, timeout: float = HANG_S) -> list[dict]:
        deadline = time.monotonic() + timeout
        while True:
            with self.lock:
                if len(self.proposals) >= count:
                    return list(self.proposals)
            assert time.monotonic() < deadline, f"expected {count} proposals messages, got {self.proposals}"
            time.sleep(0.02)


@pytest.fixture
def client(lab_session):
    """The session's lab client with nothing recorded yet (messages of earlier tests' nodes are dropped)."""
    with lab_session.lock:
        lab_session.events.clear()
        lab_session.proposals.clear()
        lab_session.statuses.clear()
    return lab_session


@contextmanager
def spinning(node: Node):
    """The node, spun by an executor of its own in a background thread until the block ends; then destroyed."""
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    try:
        yield node
    finally:
        executor.shutdown()
        node.destroy_node()


@pytest.fixture(scope="session")
def lab_session():
    rclpy.init()
    with spinning(Client()) as node:
        yield node
    rclpy.try_shutdown()


def node_env(tmp_path: Path) -> dict[str, str]:
    env = ros_environment()
    env["ROS_LOG_DIR"] = str(tmp_path / "ros_logs")
    env["PYTHONFAULTHANDLER"] = "1"  # a node that crashes, or is sent SIGABRT, prints every thread's stack
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(PLUGIN_PATH), env.get("PYTHONPATH")]))
    return env


class PlannerProcess:
    def __init__(self, tmp_path: Path, config: dict, ros_args: tuple[str, ...] = (), **params):
        self.config_path = tmp_path / f"config-{len(list(tmp_path.glob('config-*')))}.yaml"
        self.config_path.write_text(yaml.safe_dump(config))
        params.setdefault("storage", str(tmp_path / "campaign.sqlite"))
        params.setdefault("seed", 0)
        args = ["--ros-args", *ros_args, "-p", f"config:={self.config_path}"]
        for key, value in params.items():
            args += ["-p", f"{key}:={str(value).lower() if isinstance(value, bool) else value}"]
        self.log_path = tmp_path / f"planner-{self.config_path.stem}.log"
        self.log = open(self.log_path, "a")
        # owned by a supervisor: stopped in order at the end of the test, and gone with the test process if that
        # is killed (a node finishes an ask in flight before it exits, hence the long stop timeout)
        self.supervisor = Supervisor(stop_timeout_s=HANG_S)
        self.process = self.supervisor.start("planner node", [sys.executable, "-m", "gryffin_ros.nodes.planner_node",
                                                              *args], node_env(tmp_path), stdout=self.log,
                                             stderr=subprocess.STDOUT)

    def output(self) -> str:
        if not self.log.closed:
            self.log.flush()
        return self.log_path.read_text()

    def stop(self) -> int:
        self.supervisor.stop()
        self.log.close()
        return self.process.returncode


@pytest.fixture
def supervisor():
    """Starts the test's other node processes (emulators); stops them at its end, and they leave with the test
    process if that is killed."""
    with Supervisor() as owner:
        yield owner


def start_emulator(supervisor: Supervisor, tmp_path: Path, *args: str) -> subprocess.Popen:
    """A flow-reactor emulator node with these `--ros-args`, its output discarded."""
    return supervisor.start("emulator node", [sys.executable, "-m", "gryffin_ros.nodes.emulator_node", "flow_reactor",
                                              "--ros-args", *args], node_env(tmp_path), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """A failed test's report carries the end of its planner nodes' output (CI keeps nothing else of them)."""
    outcome = yield
    report = outcome.get_result()
    if report.failed:
        for process in getattr(item, "planner_processes", []):
            report.sections.append((f"planner node output ({process.log_path.name}, last 200 lines)",
                                    "\n".join(process.output().splitlines()[-200:])))


def why_unanswered(session: Client, planner: PlannerProcess, statuses_before: int, tmp_path: Path) -> str:
    """What to say when a planner never answered this test process: whether DDS works from the planner to this
    process (its latched status arrived after `statuses_before` of them), from this process to it (the JSON bridge's
    ~/json/get_status, another client of this process's participant), and from a new process; then the planner is
    sent SIGABRT, so its output (in the failure's report) ends with the stack of each of its threads."""
    with session.lock:
        statuses = len(session.statuses) - statuses_before
    try:
        session.call(session.status_client, timeout=QUERY_RESEND_S)
        bridge = "answered"
    except AssertionError:
        bridge = "no answer"
    try:
        probe = subprocess.run([sys.executable, "-m", "tests.nodes.probe_status", "/gryffin_planner", "30"],
                               cwd=Path(__file__).resolve().parents[2], env=node_env(tmp_path), capture_output=True,
                               text=True, timeout=HANG_S)
        fresh = probe.stdout.strip() or probe.stderr[-500:]
    except subprocess.TimeoutExpired:
        fresh = f"the probe itself hung for {HANG_S:.0f} s"
    alive = planner.process.poll() is None
    if alive:
        planner.process.send_signal(signal.SIGABRT)
        planner.process.wait(timeout=HANG_S)
    return (f"planner {'running' if alive else f'exited ({planner.process.returncode})'}; its latched status reached "
            f"this process {statuses} time(s) since the restart; ~/json/get_status from this process: {bridge}; "
            f"~/get_status from a new process: {fresh}")


@pytest.fixture
def start_planner(request, tmp_path, lab_session):
    """Start a planner node; unless told otherwise wait until it runs and its latched status reached the lab client
    (a node of an earlier test may still be known to DDS for a moment, so its service is no sign of the new one)."""
    started: list[PlannerProcess] = []
    request.node.planner_processes = started

    def start(config: dict = FLOW_CONFIG, wait: bool = True, ros_args: tuple[str, ...] = (),
              **params) -> PlannerProcess:
        with lab_session.lock:
            seen = len(lab_session.statuses)
        process = PlannerProcess(tmp_path, config, ros_args, **params)
        started.append(process)
        deadline = time.monotonic() + HANG_S
        while wait:
            if params.get("autostart") is False and "autostart is off" in process.output():
                break  # unconfigured: nothing is published yet
            with lab_session.lock:
                # the default namespace's status reached the lab client, or a namespaced node says it is active
                if ((len(lab_session.statuses) > seen or ros_args) and "campaign '" in process.output()
                        and ": active" in process.output()):
                    break
            assert process.process.poll() is None, f"planner node exited: {process.output()}"
            assert time.monotonic() < deadline, "planner node did not come up"
            time.sleep(0.05)
        return process
    yield start
    for process in started:
        process.stop()
