# The two commands of the README: `make demo` runs the main job, `make test` the test suite. Each first creates or
# refreshes the local virtual environment (torch pinned through constraints.txt, then the package with its test,
# ROS 2 and GP extras).
VENV ?= .venv
PYTHON ?= python3
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

# DDS stays on loopback in every process started from here (SPEC section 6), with the fast-discovery profile.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
export FASTRTPS_DEFAULT_PROFILES_FILE := $(CURDIR)/gryffin_ros/resources/fastdds_profile.xml
export RMW_IMPLEMENTATION := rmw_fastrtps_cpp

.PHONY: venv demo test lint

$(STAMP): setup.py constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt torch==2.13.0
	$(PY) -m pip install --quiet -c constraints.txt -e '.[test,ros,gp]'
	touch $(STAMP)

venv: $(STAMP)

demo: venv
	$(VENV)/bin/gryffin-ros campaign

# Each test run gets its own ROS domain (1-101) so parallel runs on one machine never see each other.
test: venv
	ROS_DOMAIN_ID=$${ROS_DOMAIN_ID:-$$(( $$$$ % 101 + 1 ))} ROS_LOG_DIR=$$(mktemp -d) $(PY) -m pytest -q tests

lint: venv
	$(VENV)/bin/ruff check gryffin_ros tests benchmarks
