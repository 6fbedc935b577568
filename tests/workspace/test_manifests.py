"""The two package manifests are what colcon and an apt ROS 2 Jazzy read: package.xml format 3, valid (catkin_pkg,
the parser colcon-ros and rosdep use), with the build types the packages are built with."""

from __future__ import annotations

from pathlib import Path

from catkin_pkg.package import parse_package

REPO = Path(__file__).resolve().parents[2]


def test_package_manifests_are_format_3_with_the_build_types_ros_expects():
    manifests = {name: REPO / name / "package.xml" for name in ("gryffin_ros", "gryffin_ros_msgs")}
    build_types = {"gryffin_ros": "ament_python", "gryffin_ros_msgs": "ament_cmake"}
    for name, path in manifests.items():
        package = parse_package(str(path))
        package.validate()
        assert package.name == name and package.package_format == 3
        assert package.get_build_type() == build_types[name]
    gryffin = parse_package(str(manifests["gryffin_ros"]))
    assert "gryffin_ros_msgs" in {d.name for d in gryffin.exec_depends}
