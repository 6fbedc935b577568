"""Bad configs (each known way to break one) and parameters (fuzzed) at start-up: always a clear message and exit code
2, never a half-started node."""

import json
import subprocess
import sys

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from .conftest import FLOW_CONFIG, node_env

# each a node process of its own (2-3 s of imports each), started all at once
BROKEN_CONFIGS = [
    {**FLOW_CONFIG, "parameters": []},
    {**FLOW_CONFIG, "objectives": [{"name": "X1_X2", "goal": "sideways"}]},
    {**FLOW_CONFIG, "constraints": ["F_C +"]},
    {**FLOW_CONFIG, "constraints": ["__import__('os').system('true')"]},
    {**FLOW_CONFIG, "constraints": ["F_C < 10", "F_C > 100"]},
    {**FLOW_CONFIG, "constraints": [{"plugin": "lookup", "options": {"file": "/nonexistent.csv"}}]},
    {**FLOW_CONFIG, "general": {"batches": -3}},
    {**FLOW_CONFIG, "unknown_section": {}},
    *({**FLOW_CONFIG, "parameters": [{**FLOW_CONFIG["parameters"][0], bound: "NaN"}, *FLOW_CONFIG["parameters"][1:]]}
      for bound in ("low", "high")),
    {**FLOW_CONFIG, "name": "  "},
    {"parameters": "F_C"},
]
BAD_PARAMETERS = st.sampled_from([["batch_size:=0"], ["acquisition_optimizer:=lbfgs"], ["max_message_bytes:=10"]])


def launch(folder, config, parameters) -> subprocess.Popen:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "config.json"
    path.write_text(json.dumps(config))
    args = ["--ros-args", "-p", f"config:={path}", "-p", "storage:=\":memory:\""]
    for parameter in parameters:
        args += ["-p", parameter]
    return subprocess.Popen([sys.executable, "-m", "gryffin_ros.nodes.planner_node", *args], env=node_env(folder),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def start(tmp_path, config, parameters) -> subprocess.CompletedProcess:
    process = launch(tmp_path, config, parameters)
    stdout, stderr = process.communicate(timeout=120)
    return subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)


def test_broken_configs_stop_the_node_with_a_message(tmp_path):
    processes = [launch(tmp_path / str(k), config, []) for k, config in enumerate(BROKEN_CONFIGS)]
    try:
        for config, process in zip(BROKEN_CONFIGS, processes):
            stdout, stderr = process.communicate(timeout=300)
            assert process.returncode == 2, (config, stdout + stderr)
            assert "gryffin_planner: cannot start:" in stderr, (config, stderr)
    finally:
        for process in processes:
            process.kill()
            process.wait()


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
