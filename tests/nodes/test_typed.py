"""The ROS-native planner node over real DDS, seen from a separate rclpy process that imports gryffin_ros_msgs: the
lifecycle, the Recommend action (feedback, result, cancel), typed observations and events, parameters, diagnostics,
namespaces."""

from __future__ import annotations

import math
import signal
import sqlite3
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
import yaml
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from gryffin_ros_msgs.action import Recommend
from gryffin_ros_msgs.msg import Event, ObjectiveValue, Observation, ParameterValue
from gryffin_ros_msgs.srv import GetStatus
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
from rcl_interfaces.msg import Parameter, ParameterType
from rcl_interfaces.msg import ParameterValue as RosParameterValue
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.qos import qos_profile_system_default

from gryffin_ros.nodes.qos import EVENTS_QOS, OBSERVATIONS_QOS
from gryffin_ros.paths import share_path

from .conftest import FLOW_CONFIG, HANG_S, flow_feasible, node_env, query, spinning, start_emulator, why_unanswered

EXAMPLES = share_path("examples")
# client rule (docs/ros.md): a goal not accepted within this long is sent again under the same instrument name; a
# busy 2-core machine accepts one in well under a second, so a resend happens only when a request or its answer was
# lost (while a restarted planner is being matched)
RESEND_S = 5.0
# an accepted goal whose result has not come this long after is sent again too (an ask takes about a second there)
RESULT_RESEND_S = 30.0


class Gate:
    """A campaign whose recommendations can be held in the middle of their optimization: its `test_gate` constraint
    plugin (tests/plugin_package) waits while the file `hold` exists. A cancel or a stop then always arrives while the
    recommendation runs, however fast the machine (a long ask only made that likely: a fast CI machine finished one
    of 400 points before the cancel came)."""

    def __init__(self, tmp_path: Path) -> None:
        self.hold = tmp_path / "hold"
        self.held = tmp_path / "hold.held"
        self.config = {
            "name": "held_test",
            "parameters": [{"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 1.0} for i in range(3)],
            "objectives": [{"name": "y", "goal": "min"}],
            "constraints": ["x0 + x1 < 1.5", {"plugin": "test_gate", "options": {"hold": str(self.hold)}}],
            "general": {"surrogate": "kde"},
        }

    def held_goal(self, lab: TypedLab, feedback: list | None = None):
        """A Recommend goal, accepted and held at the gate."""
        self.held.unlink(missing_ok=True)
        self.hold.touch()
        goal = lab.send_goal(3, feedback)
        assert goal.accepted
        wait_until(self.held.exists, "the recommendation held at the gate")
        return goal

    def release(self) -> None:
        self.hold.unlink()


def wait_until(condition, what: str, timeout: float = HANG_S, fail: bool = True):
    deadline = time.monotonic() + timeout
    while not (value := condition()):
        if time.monotonic() > deadline:
            assert not fail, f"timed out waiting for {what}"
            return value
        time.sleep(0.02)
    return value


class TypedLab(Node):
    """A lab client that uses the typed interfaces of the planner in namespace `ns`."""

    def __init__(self, name: str, ns: str = "") -> None:
        super().__init__(name)
        base = f"{ns}/gryffin_planner"
        self.events: list[Event] = []
        self.diagnostics: list[DiagnosticArray] = []
        self.lock = threading.Lock()
        self.observations = self.create_publisher(Observation, f"{base}/observations", OBSERVATIONS_QOS)
        self.create_subscription(Event, f"{base}/events", self._keep(self.events), EVENTS_QOS)
        self.create_subscription(DiagnosticArray, "/diagnostics", self._keep(self.diagnostics), 10)
        self.recommend = ActionClient(self, Recommend, f"{base}/recommend")
        self.get_status = self.create_client(GetStatus, f"{base}/get_status")
        self.change_state = self.create_client(ChangeState, f"{base}/change_state")
        self.get_state = self.create_client(GetState, f"{base}/get_state")
        self.set_parameters = self.create_client(SetParameters, f"{base}/set_parameters",
                                                 qos_profile=qos_profile_system_default)
        self.get_parameters = self.create_client(GetParameters, f"{base}/get_parameters")

    def _keep(self, sink: list):
        def callback(msg) -> None:
            with self.lock:
                sink.append(msg)
        return callback

    @staticmethod
    def wait(future, what: str, timeout: float = HANG_S):
        wait_until(future.done, what, timeout)
        return future.result()

    def call(self, client, request, timeout: float = HANG_S):
        assert client.wait_for_service(timeout_sec=timeout), f"{client.srv_name} not available"
        return self.wait(client.call_async(request), f"an answer from {client.srv_name}", timeout)

    def state(self) -> str:
        return query(self.get_state, GetState.Request()).current_state.label

    def transition(self, transition_id: int) -> bool:
        """A lifecycle transition, sent once (sending it again is not the same request); an answered query to the
        node first shows that both sides have matched each other."""
        self.state()
        return self.call(self.change_state, ChangeState.Request(transition=Transition(id=transition_id))).success

    def status(self):
        return query(self.get_status, GetStatus.Request()).status

    def send_goal(self, count: int, feedback: list | None = None):
        """A Recommend goal under this client's instrument name, sent again while its acceptance does not arrive
        (docs/ros.md, client rules: a request can be lost while a restarted planner is being matched; the planner
        hands a repeated ask by the same instrument the experiments it already claimed)."""
        deadline = time.monotonic() + HANG_S
        while True:
            assert self.recommend.wait_for_server(timeout_sec=HANG_S), "recommend action server not available"
            future = self.recommend.send_goal_async(Recommend.Goal(count=count, instrument=self.get_name()),
                                                    feedback_callback=None if feedback is None else feedback.append)
            answered = wait_until(future.done, "the goal's acceptance", RESEND_S, fail=False)
            if answered:
                return future.result()
            assert time.monotonic() < deadline, f"no goal accepted in {HANG_S:.0f} s of resending"

    def recommend_now(self, count: int = 0, feedback: list | None = None):
        """The result of a Recommend goal; the goal is sent again when its acceptance or its result is lost."""
        deadline = time.monotonic() + HANG_S
        while True:
            goal = self.send_goal(count, feedback)
            assert goal.accepted, "goal rejected"
            result = goal.get_result_async()
            if wait_until(result.done, "the recommendation's result", RESULT_RESEND_S, fail=False):
                return result.result()
            assert time.monotonic() < deadline, f"no result in {HANG_S:.0f} s of resending"

    def set(self, name: str, value) -> tuple[bool, str]:
        kinds = {bool: (ParameterType.PARAMETER_BOOL, "bool_value"), int: (ParameterType.PARAMETER_INTEGER,
                 "integer_value"), str: (ParameterType.PARAMETER_STRING, "string_value")}
        kind, field = kinds[type(value)]
        parameter = Parameter(name=name, value=RosParameterValue(type=kind, **{field: value}))
        result = self.call(self.set_parameters, SetParameters.Request(parameters=[parameter])).results[0]
        return result.successful, result.reason

    def observation_events(self, count: int) -> list[Event]:
        def enough():
            with self.lock:
                got = [e for e in self.events if e.type.startswith("observation_")]
            return got if len(got) >= count else None
        return wait_until(enough, f"{count} observation events")

    def wait_matched(self) -> None:
        wait_until(lambda: self.observations.get_subscription_count() > 0, "the planner's observation subscription")


@pytest.fixture
def lab(lab_session):
    """A typed lab client in this test process (rclpy is initialized by the session's JSON client)."""
    with spinning(TypedLab("typed_lab")) as node:
        yield node


def observation_of(proposal, objectives: dict[str, float] | None, **changes) -> Observation:
    params = [ParameterValue(name=p.name, number=changes.get(p.name, p.number), text=p.text) for p in proposal.params]
    return Observation(experiment_id=proposal.experiment_id, params=params, failed=objectives is None,
                       objectives=[ObjectiveValue(name=k, value=v) for k, v in (objectives or {}).items()])


def params_dict(proposal) -> dict:
    return {p.name: (p.text or p.number) for p in proposal.params}


def test_a_managed_node_is_configured_and_activated_then_recommends_and_learns(lab, start_planner):
    start_planner(autostart=False, auto_propose=False)
    assert lab.state() == "unconfigured"
    diagnosis = wait_until(lambda: next((d.status[0] for d in list(lab.diagnostics)
                                         if d.status[0].message == "unconfigured"), None), "diagnostics unconfigured")
    assert diagnosis.level == DiagnosticStatus.WARN  # not serving
    assert lab.transition(Transition.TRANSITION_CONFIGURE)
    assert lab.state() == "inactive"
    assert lab.transition(Transition.TRANSITION_ACTIVATE)
    assert lab.state() == "active"

    feedback: list = []
    outcome = lab.recommend_now(3, feedback)
    assert outcome.status == 4, outcome  # GoalStatus.STATUS_SUCCEEDED
    proposals = outcome.result.proposals
    assert len(proposals) == 3 and all(flow_feasible(params_dict(p)) for p in proposals)
    assert len({p.experiment_id for p in proposals}) == 3
    assert all(math.isnan(p.strategy) or -1 <= p.strategy <= 1 for p in proposals)
    assert feedback and all(0.0 <= f.feedback.progress <= 1.0 for f in feedback)
    assert lab.status().n_pending == 3

    lab.wait_matched()
    first, second, third = proposals
    lab.observations.publish(observation_of(first, {"X1_X2": 0.4}))
    lab.observations.publish(observation_of(second, {"X1_X2": 0.4}, T=180.0))  # above the bound
    lab.observations.publish(observation_of(second, {"X1_X2": math.nan}))  # NaN is not a result
    lab.observations.publish(observation_of(second, None))  # failed: data
    lab.observations.publish(observation_of(third, {"X1_X2": 0.1}, F_C=150.0, F_S=10.0))  # infeasible
    events = lab.observation_events(5)
    assert [(e.type, e.experiment_id) for e in events] == [
        ("observation_accepted", first.experiment_id), ("observation_rejected", second.experiment_id),
        ("observation_rejected", second.experiment_id), ("observation_accepted", second.experiment_id),
        ("observation_rejected", third.experiment_id)]
    assert "'T' = 180.0 is above its upper bound 150.0" in events[1].reason
    assert "failed = true" in events[2].reason
    assert "violate the known constraint" in events[4].reason
    status = lab.status()
    assert (status.n_observations, status.n_failed, status.n_pending) == (2, 1, 1)
    assert status.best[0].experiment_id == first.experiment_id

    def active_diagnosis():
        for array in reversed(list(lab.diagnostics)):
            values = {v.key: v.value for v in array.status[0].values}
            if values.get("observations") == "2":
                return array.status[0], values
        return None
    diagnosis, values = wait_until(active_diagnosis, "diagnostics with the observations")
    assert values["lifecycle_state"] == "active" and values["pending"] == "1" and values["failed"] == "1"
    assert diagnosis.level == DiagnosticStatus.WARN and "rejected" in diagnosis.message  # recent rejections

    assert lab.transition(Transition.TRANSITION_DEACTIVATE)
    assert lab.state() == "inactive"
    assert lab.transition(Transition.TRANSITION_CLEANUP)
    assert lab.state() == "unconfigured"


def learn_two_results(lab: TypedLab) -> None:
    """Two results reported, so that the next recommendation builds a model and optimizes it."""
    first = lab.recommend_now(2).result.proposals
    lab.wait_matched()
    for i, proposal in enumerate(first):
        lab.observations.publish(observation_of(proposal, {"y": float(i)}))
    lab.observation_events(2)


def stopping_logged(planner) -> bool:
    return "recommendation(s) in progress" in planner.output()


def test_a_running_recommendation_is_canceled_and_leaves_nothing_pending(lab, start_planner, tmp_path):
    gate = Gate(tmp_path)
    planner = start_planner(gate.config, auto_propose=False)
    learn_two_results(lab)
    feedback: list = []
    goal = gate.held_goal(lab, feedback)
    answer = lab.wait(goal.cancel_goal_async(), "the cancel response")
    assert answer.return_code == 0 and len(answer.goals_canceling) == 1  # CancelGoal ERROR_NONE: taken
    gate.release()
    outcome = lab.wait(goal.get_result_async(), "the canceled result")
    assert outcome.status == 5, outcome  # GoalStatus.STATUS_CANCELED
    assert not outcome.result.proposals and "canceled" in outcome.result.error
    assert outcome.result.n_observations == 2
    status = lab.status()
    assert (status.n_pending, status.state) == (0, "idle")
    after = lab.recommend_now(1)  # the node goes on serving
    assert after.status == 4 and len(after.result.proposals) == 1

    # a deactivation stops a running recommendation too (aborted, nothing stored), and activation resumes serving
    goal = gate.held_goal(lab)
    transition = lab.change_state.call_async(ChangeState.Request(
        transition=Transition(id=Transition.TRANSITION_DEACTIVATE)))
    wait_until(lambda: stopping_logged(planner), "the node stopping the held recommendation")
    assert "was deactivated" in planner.output()
    gate.release()
    outcome = lab.wait(goal.get_result_async(), "the aborted result")
    assert outcome.status == 6 and "deactivated" in outcome.result.error, outcome  # GoalStatus.STATUS_ABORTED
    assert lab.wait(transition, "the deactivation").success
    assert lab.transition(Transition.TRANSITION_ACTIVATE)
    assert lab.status().n_pending == 1  # the one of `after`, still owed
    assert lab.recommend_now(1).status == 4


def test_a_recommendation_running_when_the_node_is_stopped_is_aborted_with_the_reason(lab, start_planner, tmp_path):
    gate = Gate(tmp_path)
    planner = start_planner(gate.config, auto_propose=False)
    learn_two_results(lab)
    goal = gate.held_goal(lab)
    planner.process.send_signal(signal.SIGINT)  # Ctrl-C, as an operator stops a node
    wait_until(lambda: stopping_logged(planner), "the node stopping the held recommendation")
    gate.release()
    outcome = lab.wait(goal.get_result_async(), "the aborted result")
    assert outcome.status == 6, outcome  # GoalStatus.STATUS_ABORTED
    assert "shutting down" in outcome.result.error and not outcome.result.proposals
    assert planner.process.wait(timeout=HANG_S) == 0
    assert "never retrieved" not in planner.output() and "Traceback" not in planner.output()


def test_parameters_are_validated_when_set_and_read_only_ones_refuse(lab, start_planner):
    start_planner(auto_propose=False)
    ok, reason = lab.set("batch_size", 0)
    assert not ok and "at least 1" in reason
    ok, reason = lab.set("acquisition_optimizer", "simplex")
    assert not ok and "'adam', 'genetic' or empty" in reason
    ok, _ = lab.set("storage", "/tmp/elsewhere.sqlite")
    assert not ok  # read-only
    ok, _ = lab.set("batch_size", "three")
    assert not ok  # wrong type
    assert lab.set("batch_size", 2) == (True, "")
    assert lab.set("acquisition_optimizer", "genetic") == (True, "")
    assert len(lab.recommend_now(0).result.proposals) == 2  # count 0: the node's batch_size, as set


def test_the_params_file_example_configures_the_node(lab, start_planner, tmp_path):
    example = EXAMPLES / "planner_params.yaml"
    start_planner(wait=True, ros_args=("--params-file", str(example)), storage=str(tmp_path / "p.sqlite"))
    answer = query(lab.get_parameters, GetParameters.Request(names=["batch_size", "max_message_bytes"]))
    assert [v.integer_value for v in answer.values] == [2, 65536]


def test_a_failed_configure_leaves_the_node_unconfigured_and_says_why(lab, start_planner, tmp_path):
    config = dict(FLOW_CONFIG, parameters=[{"name": "T", "type": "continuous", "low": 150.0, "high": 100.0}],
                  constraints=[])
    start_planner(config, autostart=False)
    assert not lab.transition(Transition.TRANSITION_CONFIGURE)
    assert lab.state() == "unconfigured"
    diagnosis = wait_until(lambda: next((d.status[0] for d in list(lab.diagnostics)
                                         if d.status[0].message.startswith("configure failed")), None),
                           "diagnostics naming the failure")
    assert diagnosis.level == DiagnosticStatus.ERROR and "'T'" in diagnosis.message


def stored_ids(path: Path) -> tuple[set[str], set[str], int]:
    with sqlite3.connect(path) as db:
        observed = {r[0] for r in db.execute("SELECT experiment_id FROM observations")}
        proposed = {r[0] for r in db.execute("SELECT experiment_id FROM proposals")}
        rejected = db.execute("SELECT COUNT(*) FROM rejections").fetchone()[0]
    return observed, proposed, rejected


def test_two_campaigns_in_two_namespaces_do_not_cross(start_planner, supervisor, tmp_path):
    stores = {}
    try:
        for ns, seed in (("/lab1", 1), ("/lab2", 2)):
            stores[ns] = tmp_path / f"{ns.strip('/')}.sqlite"
            start_planner(ros_args=("-r", f"__ns:={ns}"), storage=str(stores[ns]), seed=seed)
            start_emulator(supervisor, tmp_path, "-r", f"__ns:={ns}", "-p", f"seed:={seed}", "-p",
                           "objectives:=[X1_X2]")
        wait_until(lambda: all(len(stored_ids(s)[0]) >= 4 for s in stores.values()), "4 experiments in each lab")
    finally:
        supervisor.stop()  # the emulators, by SIGINT (a SIGKILLed participant can stall the others: Fast-DDS#5469)
    (observed1, proposed1, rejected1), (observed2, proposed2, rejected2) = (stored_ids(s) for s in stores.values())
    assert observed1 <= proposed1 and observed2 <= proposed2
    assert not proposed1 & proposed2
    assert rejected1 == rejected2 == 0  # no observation of the other lab ever reached a planner


def readme_client() -> str:
    """The typed lab client of the README's ROS section, as written."""
    text = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    section = text[text.index("## From ROS 2"):]
    start = section.index("```python\n") + len("```python\n")
    return section[start:section.index("```", start)]


def test_the_readme_typed_client_runs_as_written(start_planner, tmp_path):
    config = yaml.safe_load((EXAMPLES / "flow_reactor.yaml").read_text())
    store = tmp_path / "readme.sqlite"
    start_planner(config, storage=str(store), auto_propose=False)
    script = tmp_path / "lab.py"
    instrument = ("def run_my_experiment(F_C, F_S, T):\n"
                  "    return None if T > 149 else {'X1_X2': F_S / (F_C + F_S), 'cost': 0.001 * F_C}\n")
    script.write_text(instrument + readme_client() + "rclpy.spin(node)\n")
    client = subprocess.Popen([sys.executable, str(script)], env=node_env(tmp_path), stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
    try:
        wait_until(lambda: client.poll() is not None or len(stored_ids(store)[0]) == 2, "the README client's results")
    finally:
        client.send_signal(signal.SIGINT)  # not SIGKILL (eProsima/Fast-DDS#5469: it can stall the other processes)
        try:
            output = client.communicate(timeout=HANG_S)[0]
        except subprocess.TimeoutExpired:
            client.kill()
            output = client.communicate()[0]
    assert len(stored_ids(store)[0]) == 2, output
    assert "optimizing" in output or "models" in output  # the feedback stages it prints


def test_after_a_restart_a_client_that_retries_gets_the_experiment_still_owed(lab, lab_session, start_planner,
                                                                             tmp_path):
    """A killed node's services and action still look available to DDS for a while, so a request can go to the dead
    node; the documented client rule: probe ~/get_status with a timeout, retry until it answers, then send goals."""
    store = tmp_path / "restart.sqlite"
    planner = start_planner(storage=str(store), auto_propose=False)
    (owed,) = lab.recommend_now(1).result.proposals
    planner.process.kill()
    planner.process.wait()
    with lab_session.lock:
        statuses = len(lab_session.statuses)
    restarted = start_planner(storage=str(store), auto_propose=False, wait=False)
    # a restarted node answers within seconds; once, in a full `make test`, it never did (400 s; cause unknown):
    # the failure then says which direction of DDS still worked
    give_up = time.monotonic() + HANG_S
    while True:
        assert time.monotonic() < give_up, (
            f"the restarted planner never answered: {why_unanswered(lab_session, restarted, statuses, tmp_path)}")
        if not lab.get_status.wait_for_service(timeout_sec=1.0):
            continue
        future = lab.get_status.call_async(GetStatus.Request())
        deadline = time.monotonic() + 2.0
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.02)
        if future.done():
            break
        lab.get_status.remove_pending_request(future)
    (again,) = lab.recommend_now(1).result.proposals
    assert again.experiment_id == owed.experiment_id  # still owed, handed out first
