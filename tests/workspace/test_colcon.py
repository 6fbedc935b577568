"""The repository as a colcon workspace's source (README, "In a colcon workspace"): a bare `colcon build` finds and
builds both packages (gryffin_ros_msgs/ with ament_cmake, gryffin_ros/ with ament_python) and nothing else of the
repository, in an environment holding the ROS
2 wheels and colcon, no apt ROS; after `source install/setup.bash` the planner node runs from the installed layout
(`install/gryffin_ros/lib/gryffin_ros/planner_node`, what `ros2 run gryffin_ros planner_node` starts) with the installed
params file and example, and serves a typed Recommend goal to a client that imports the installed packages.

The workspace is built once (a plain build, as a lab does; about 2 minutes on 2 cores)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import pytest
import yaml

from gryffin_ros.nodes.rosenv import ros_environment
from gryffin_ros.nodes.supervisor import Supervisor

pytestmark = [pytest.mark.ros, pytest.mark.slow]

REPO = Path(__file__).resolve().parents[2]
CLIENT = Path(__file__).with_name("recommend_client.py")
BUILD_TIMEOUT_S = 1200.0
HANG_S = 180.0
# the commands of the README's section
BUILD = ["colcon", "build"]


def underlay_environment(log_dir: Path) -> dict[str, str]:
    """What a lab's shell has before `colcon build`: this environment's bin/ first on PATH (its `colcon`, `cmake`'s
    view of the ROS packages in it), the environment as the ROS underlay (AMENT_PREFIX_PATH, CMAKE_PREFIX_PATH: what
    sourcing /opt/ros/jazzy/setup.bash does for an apt ROS), DDS on loopback in the test's domain; no PYTHONPATH, so
    nothing of the source tree leaks into the installed layout."""
    env = ros_environment()
    env.pop("PYTHONPATH", None)
    env.pop("_ROS_WHEELS_BOOTSTRAP_COMPLETE", None)  # a fresh shell's python sets up the wheels' library path itself
    env["VIRTUAL_ENV"] = sys.prefix
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "/usr/bin:/bin")])
    env["AMENT_PREFIX_PATH"] = env["CMAKE_PREFIX_PATH"] = sys.prefix
    env["ROS_LOG_DIR"] = str(log_dir)
    return env


def copy_sources(destination: Path) -> None:
    """The repository's files as a clone has them (tracked, and new ones not ignored), without build outputs."""
    if not (REPO / ".git").exists():
        pytest.fail(f"{REPO} is not a git checkout: this test copies the files git lists into a workspace")
    files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=REPO,
                           check=True, capture_output=True).stdout.decode().split("\0")
    for name in filter(None, files):
        source = REPO / name
        if source.is_file():
            (destination / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, destination / name)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    """A built workspace: (its root, the environment after `source install/setup.bash`)."""
    root = tmp_path_factory.mktemp("colcon_ws")
    copy_sources(root / "src" / "gryffin_ros")
    env = underlay_environment(root / "ros_logs")
    assert shutil.which("colcon", path=env["PATH"]), "no colcon: install the 'workspace' extra (make does)"
    with open(root / "build.log", "w") as log:
        built = subprocess.run(BUILD, cwd=root, env=env, stdout=log, stderr=subprocess.STDOUT,
                               timeout=BUILD_TIMEOUT_S)
    assert built.returncode == 0, f"colcon build failed:\n{(root / 'build.log').read_text()[-4000:]}"
    dumped = subprocess.run(["bash", "-c", "source install/setup.bash && env -0"], cwd=root, env=env, check=True,
                            capture_output=True).stdout.decode()
    sourced = dict(item.split("=", 1) for item in dumped.split("\0") if "=" in item)
    return root, sourced


def check_the_ros_layout(root: Path, env: dict[str, str]) -> None:
    install = root / "install"
    # exactly the two packages: colcon found both folders and no other folder of the repository as a package
    assert {p.name for p in install.iterdir() if p.is_dir()} == {"gryffin_ros", "gryffin_ros_msgs"}
    for package in ("gryffin_ros", "gryffin_ros_msgs"):
        assert (install / package / "share/ament_index/resource_index/packages" / package).is_file()
        assert (install / package / "share" / package / "package.xml").is_file()
        assert str(install / package) in env["AMENT_PREFIX_PATH"].split(os.pathsep)
    for name in ("planner_node", "flow_reactor_node", "redox_node", "gryffin-ros"):
        executable = install / "gryffin_ros/lib/gryffin_ros" / name
        assert executable.is_file() and os.access(executable, os.X_OK), name
    share = install / "gryffin_ros/share/gryffin_ros"
    for name in ("examples/planner_params.yaml", "examples/flow_reactor.yaml", "examples/redox_flow_battery.yaml",
                 "examples/redox_feasible_959.csv", "msg_schemas/observation.schema.json"):
        assert (share / name).is_file(), name
    # the installed Python packages are the ones imported, not the source tree's or the environment's
    imported = subprocess.run([sys.executable, "-c", "import gryffin_ros, gryffin_ros_msgs.action as a; "
                               "from gryffin_ros.paths import share_path; "
                               "print(gryffin_ros.__file__, a.__file__, share_path('examples'))"],
                              cwd=root, env=env, check=True, capture_output=True, text=True).stdout.split()
    assert imported[0].startswith(str(install / "gryffin_ros/lib"))
    assert imported[1].startswith(str(install / "gryffin_ros_msgs/lib"))
    assert imported[2] == str(share / "examples")


def test_the_workspace_builds_both_packages_and_the_installed_planner_node_serves_a_recommend_goal(workspace,
                                                                                                     tmp_path):
    """One test, so that pytest-xdist never splits it over two workers (each would build the workspace)."""
    root, env = workspace
    check_the_ros_layout(root, env)
    share = root / "install/gryffin_ros/share/gryffin_ros"
    node = root / "install/gryffin_ros/lib/gryffin_ros/planner_node"
    storage = tmp_path / "flow.sqlite"
    # the installed params file as a lab uses it; its config path is relative to the start directory, so named here
    argv = [str(node), "--ros-args", "--params-file", str(share / "examples/planner_params.yaml"),
            "-p", f"config:={share / 'examples/flow_reactor.yaml'}", "-p", f"storage:={storage}"]
    batch_size = yaml.safe_load((share / "examples/planner_params.yaml").read_text())[
        "/**/gryffin_planner"]["ros__parameters"]["batch_size"]
    with open(tmp_path / "planner.log", "w") as log, Supervisor(stop_timeout_s=HANG_S) as supervisor:
        planner = supervisor.start("installed planner node", argv, env, cwd=tmp_path, stdout=log,
                                   stderr=subprocess.STDOUT)
        try:
            client = subprocess.run([sys.executable, str(CLIENT), "0", str(HANG_S)], cwd=tmp_path, env=env,
                                    capture_output=True, text=True, timeout=HANG_S + 60)
        finally:
            alive = planner.poll() is None
        assert alive, f"planner exited: {(tmp_path / 'planner.log').read_text()}"
    assert client.returncode == 0, f"{client.stderr[-3000:]}\nplanner: {(tmp_path / 'planner.log').read_text()}"
    answer = json.loads(client.stdout.strip().splitlines()[-1])
    assert answer["gryffin_ros"].startswith(str(root / "install/gryffin_ros/lib"))
    assert answer["gryffin_ros_msgs"].startswith(str(root / "install/gryffin_ros_msgs/lib"))
    assert answer["error"] == ""
    proposals = answer["proposals"]
    assert len(proposals) == batch_size  # count 0: the params file's batch_size
    assert len({uuid.UUID(p["experiment_id"]) for p in proposals}) == batch_size
    for proposal in proposals:
        assert set(proposal["params"]) == {"F_C", "F_S", "T"}
    assert storage.is_file()  # the campaign was kept where the command line said
