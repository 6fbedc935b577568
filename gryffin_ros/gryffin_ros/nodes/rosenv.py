"""The process environment every rclpy process of this project runs with: DDS discovery on loopback only, the
fast-discovery Fast DDS profile; processes this project starts (tests, campaigns, benchmarks) get a ROS domain of their
own when the caller has not chosen one, a node started by hand keeps ROS's default domain and the discovery range
its caller exported (loopback when none)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from importlib import resources


def profile_path() -> str:
    return str(resources.files("gryffin_ros").joinpath("resources/fastdds_profile.xml"))


def ros_environment(base: Mapping[str, str] | None = None, domain_id: int | None = None) -> dict[str, str]:
    env = dict(os.environ if base is None else base)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.setdefault("FASTRTPS_DEFAULT_PROFILES_FILE", profile_path())
    env.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")
    if domain_id is not None:
        env["ROS_DOMAIN_ID"] = str(domain_id)
    else:
        env.setdefault("ROS_DOMAIN_ID", str(os.getpid() % 101 + 1))
    return env


def apply_to_this_process() -> None:
    """Set the environment in this process before rclpy initializes: discovery on loopback and the fast-discovery
    profile unless the caller chose otherwise. A node started by hand keeps the domain (ROS's default 0 when unset:
    it must be found by lab clients that export nothing) and a discovery range the caller exported deliberately
    (`ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET` on a lab network, README "Across machines")."""
    env = ros_environment()
    for key in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE"):
        if os.environ.get(key):
            env[key] = os.environ[key]
        elif key == "ROS_DOMAIN_ID":
            del env[key]
    os.environ.update(env)
