"""Bad configs and parameters at start-up, fuzzed: always a clear message and exit code 2, never a half-started node."""

import json
import subprocess
import sys

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from .conftest import FLOW_CONFIG, node_env

BROKEN_CONFIGS = st.one_of(
    st.just({**FLOW_CONFIG, "parameters": []}),
    st.just({**FLOW_CONFIG, "objectives": [{"name": "X1_X2", "goal": "sideways"}]}),
    st.just({**FLOW_CONFIG, "constraints": ["F_C +"]}),
    st.just({**FLOW_CONFIG, "constraints": ["__import__('os').system('true')"]}),
    st.just({**FLOW_CONFIG, "constraints": ["F_C < 10", "F_C > 100"]}),
    st.just({**FLOW_CONFIG, "constraints": [{"plugin": "lookup", "options": {"file": "/nonexistent.csv"}}]}),
    st.just({**FLOW_CONFIG, "general": {"batches": -3}}),
    st.just({**FLOW_CONFIG, "unknown_section": {}}),
    st.sampled_from(["low", "high"]).map(lambda k: {**FLOW_CONFIG, "parameters": [
        {**FLOW_CONFIG["parameters"][0], k: "NaN"}, *FLOW_CONFIG["parameters"][1:]]}),
    st.text(max_size=30).map(lambda t: {**FLOW_CONFIG, "name": t} if t.strip() == "" else {"parameters": t}),
)
BAD_PARAMETERS = st.sampled_from([["batch_size:=0"], ["acquisition_optimizer:=lbfgs"], ["max_message_bytes:=10"]])


def start(tmp_path, config, parameters):
    path = tmp_path / "config.json"
    path.write_text(json.dumps(config))
    args = ["--ros-args", "-p", f"config:={path}", "-p", "storage:=\":memory:\""]
    for parameter in parameters:
        args += ["-p", parameter]
    return subprocess.run([sys.executable, "-m", "gryffin_ros.nodes.planner_node", *args], env=node_env(tmp_path),
                          capture_output=True, text=True, timeout=120)


@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(config=BROKEN_CONFIGS)
def test_broken_configs_stop_the_node_with_a_message(tmp_path, config):
    result = start(tmp_path, config, [])
    assert result.returncode == 2, result.stdout + result.stderr
    assert "gryffin_planner: cannot start:" in result.stderr


@settings(max_examples=3, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(parameters=BAD_PARAMETERS)
def test_bad_parameters_stop_the_node_with_a_message(tmp_path, parameters):
    result = start(tmp_path, FLOW_CONFIG, parameters)
    assert result.returncode == 2 and "cannot start" in result.stderr, result.stderr


def test_a_parameter_of_the_wrong_type_is_named_with_what_it_takes(tmp_path):
    result = start(tmp_path, FLOW_CONFIG, ["batch_size:=three"])
    assert result.returncode == 2, result.stderr
    assert "parameter 'batch_size' must be an integer" in result.stderr and "Traceback" not in result.stderr


def test_a_parameter_value_ros_cannot_parse_is_named_with_how_to_quote_it(tmp_path):
    path = tmp_path / "config.json"
    path.write_text(json.dumps(FLOW_CONFIG))
    result = subprocess.run([sys.executable, "-m", "gryffin_ros.nodes.planner_node", "--ros-args", "-p",
                             f"config:={path}", "-p", "storage:=:memory:"], env=node_env(tmp_path),
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 2, result.stderr
    assert "parameter 'storage'" in result.stderr and "quote it" in result.stderr, result.stderr
