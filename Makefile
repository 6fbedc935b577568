# The two commands of the README: `make demo` runs the main job, `make test` the test suite. Each first creates or
# refreshes the local virtual environment with exactly the package set of requirements.lock (the set the suite
# passed with), then the package itself with its test, ROS 2, interface-generator, colcon (workspace), recording and
# molecules (RDKit) extras, then
# builds the typed interfaces gryffin_ros_msgs into it (gryffin_ros_msgs/build.sh). The repository holds the two ROS 2
# packages side by side, as a colcon workspace wants them: gryffin_ros/ (the Python package in gryffin_ros/gryffin_ros)
# and gryffin_ros_msgs/.
# `make lock` regenerates requirements.lock: a fresh environment resolved from the deliberate pins of
# constraints.txt alone, frozen.
VENV ?= .venv
PYTHON ?= python3
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
LOCK := requirements.lock
EXTRAS := ./gryffin_ros[test,ros,interfaces,workspace,record,molecules]
MSGS := $(VENV)/.interfaces

# DDS stays on loopback in every process started from here (SPEC section 6), with the fast-discovery profile.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
export FASTRTPS_DEFAULT_PROFILES_FILE := $(CURDIR)/gryffin_ros/gryffin_ros/resources/fastdds_profile.xml
export RMW_IMPLEMENTATION := rmw_fastrtps_cpp

.PHONY: venv demo test check lint lock

$(STAMP): gryffin_ros/setup.py constraints.txt $(LOCK)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -c $(LOCK) pip
	$(PY) -m pip install --quiet -c $(LOCK) torch
	$(PY) -m pip install --quiet -c $(LOCK) -e '$(EXTRAS)'
	touch $(STAMP)

# the typed interfaces gryffin_ros_msgs, generated into the same environment (cmake and a C/C++ compiler needed)
$(MSGS): $(STAMP) gryffin_ros_msgs/build.sh gryffin_ros_msgs/CMakeLists.txt gryffin_ros_msgs/package.xml $(wildcard gryffin_ros_msgs/msg/*.msg gryffin_ros_msgs/srv/*.srv gryffin_ros_msgs/action/*.action)
	gryffin_ros_msgs/build.sh $(VENV)
	touch $(MSGS)

lock:
	rm -rf .venv-lock
	$(PYTHON) -m venv .venv-lock
	.venv-lock/bin/python -m pip install --quiet --upgrade pip
	.venv-lock/bin/python -m pip install --quiet -c constraints.txt torch
	.venv-lock/bin/python -m pip install --quiet -c constraints.txt -e '$(EXTRAS)'
	{ echo "# The exact package set the test suite passed with; make installs it (pip -c). Regenerate: make lock"; \
	  .venv-lock/bin/python -m pip freeze --all --exclude-editable; } > $(LOCK)
	rm -rf .venv-lock

venv: $(STAMP) $(MSGS)

demo: venv
	$(VENV)/bin/gryffin-ros campaign

# Each test run gets its own ROS domain (1-101) so parallel runs on one machine never see each other; the suite runs
# on two pytest-xdist workers, and each worker moves to a domain of its own (tests/conftest.py).
PYTEST := ROS_DOMAIN_ID=$${ROS_DOMAIN_ID:-$$(( $$$$ % 101 + 1 ))} ROS_LOG_DIR=$$(mktemp -d) $(PY) -m pytest -q -n 2 --dist worksteal
test: venv
	$(PYTEST) --durations=15 tests

# The fast tier for the inner loop: no DDS, no browser, not the statistical learning tests (markers in pytest.ini).
check: venv
	$(PYTEST) -m "not ros and not browser and not slow" tests

lint: venv
	$(VENV)/bin/ruff check gryffin_ros tests benchmarks
