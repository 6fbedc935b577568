"""gryffin_ros: constrained kernel-density Bayesian optimization for self-driving labs, as a ROS 2 node.

The algorithm lives in :mod:`gryffin_ros.planner` and runs without ROS.
"""

__version__ = "0.1.0"
