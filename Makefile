# ROSMC developer commands. `make demo` and `make test` are all a new machine needs; both run
# `make setup` first, which installs only what is missing and is a no-op the second time.
#
#   make setup   Debian packages, .venv (pinned PyPI packages), messages built into build/
#   make demo    setup, then the demo mission (scripts/rosmc_demo); DEMO_ARGS=... passes options;
#                GUI=1 also opens rviz and the command GUI on it
#   make test    setup, lint, then pytest over tests/ in PYTEST_WORKERS (2) processes;
#                PYTEST_ARGS=... passes options
#   make test-thorough  the same with the thorough hypothesis profile (nightly: many examples)
#   make test-busy      make test with two CPU-bound processes beside it (tools/beside_busy.py)
#   make bench   setup, then every bench/ script: bench/results.json, bench/results.md and the
#                figures table of docs/performance.md; BENCH=server,scale runs only those
#   make sample  setup, then record bags/samples/demo.mcap anew (after a message change)
#   make lint    ruff check, ruff format --check, mypy --strict on every rosmc_* package,
#                catkin_lint on the package (its rosdep keys checked offline: tools/rosdep_offline.sh)
#   make format  ruff format and the safe ruff fixes, in place
#   make clean   remove build/ and the tool caches (keeps .venv)

SHELL := /bin/bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := help
.DELETE_ON_ERROR:

SYSTEM_PYTHON := /usr/bin/python3
VENV := .venv
BUILD := build

# ROS 1 from Debian (actionlib for skills bound to action servers), message generation, Qt
# bindings; rviz, a virtual screen and imagemagick for the GUIs and their screenshots; xdotool
# drives them with a real mouse in tests; rostest's CMake module (add_rostest), rosdep,
# catkin_lint and catkin_tools (`catkin build`). ROSDEP_PACKAGES is what rosdep resolves the
# keys of package.xml to on Debian beyond those (the C++ halves of the ROS packages, the
# message definitions a lab's own message or action package builds against): with them
# `rosdep check --from-paths src --ignore-src` is clean after `make setup`
# (tests/integration/test_rosdep.py keeps the two lists in step with package.xml).
ROSDEP_PACKAGES := \
	libgtest-dev libgmock-dev python3-setuptools python3-yaml python3-zstandard \
	python3-rosgraph python3-roslib python3-rosgraph-msgs python3-tf2-msgs \
	ros-rosgraph-msgs ros-nav-msgs ros-tf2-msgs ros-actionlib-msgs \
	libactionlib-dev libactionlib-msgs-dev libgeometry-msgs-dev libstd-msgs-dev \
	libros-rosgraph-msgs-dev libtf2-msgs-dev libtf2-ros-dev libvisualization-msgs-dev \
	libnav-msgs-dev libinteractive-markers-dev libroslib-dev librosbag-dev librviz-dev
APT_PACKAGES := \
	python3-rospy python3-rosmaster python3-interactive-markers python3-visualization-msgs \
	python3-geometry-msgs python3-std-msgs python3-std-srvs python3-rosbag python3-rostest \
	python3-roslaunch python3-rosservice python3-rostopic python3-rosnode catkin python3-genpy python3-genmsg \
	python3-nav-msgs python3-actionlib python3-actionlib-msgs \
	ros-message-generation ros-message-runtime python3-tf2-ros python3-python-qt-binding \
	ros-geometry-msgs ros-std-msgs ros-visualization-msgs ros-std-srvs rosbash \
	python3-venv cmake make \
	xvfb rviz python3-rviz imagemagick xdotool \
	librostest-dev python3-rosdep2 catkin-lint catkin-tools \
	$(ROSDEP_PACKAGES)

# Everything the standalone message build reads. A new script, package or data folder at the
# top also counts: catkin makes devel-space relays for scripts and top-level packages.
BUILD_INPUTS := CMakeLists.txt package.xml setup.py \
	$(wildcard rosmc_msgs/msg/*.msg rosmc_msgs/srv/*.srv scripts/* rosmc_*/__init__.py)

# Every rosmc_* package (server, simulator, markers, command GUI): type-checked with
# mypy --strict. Untyped third-party modules are listed in pyproject.toml.
PACKAGES = $(patsubst %/__init__.py,%,$(wildcard rosmc_*/__init__.py))

# Run a command inside the environment of env.sh.
IN_ENV := source ./env.sh &&

.PHONY: help setup apt apt-packages venv requirements msgs demo sample test test-thorough test-busy pytest \
	bench lint format clean

help:
	@sed -n '1,/^$$/s/^# \{0,1\}//p' Makefile

setup: apt requirements msgs

apt:
	@tools/ensure_apt_packages.sh $(APT_PACKAGES)

# The Debian packages `make setup` installs, one a line (for tests and scripts).
apt-packages:
	@printf '%s\n' $(APT_PACKAGES)

# A venv made from Debian's python with --system-site-packages, so it sees ROS 1. One made
# from another python (or without system packages) is replaced.
venv: apt
	@if ! grep -qx 'include-system-site-packages = true' $(VENV)/pyvenv.cfg 2>/dev/null \
	   || [[ "$$(readlink -f $(VENV)/bin/python)" != "$$(readlink -f $(SYSTEM_PYTHON))" ]]; then \
	  echo "Creating $(VENV) from $(SYSTEM_PYTHON)"; \
	  rm -rf $(VENV); \
	  $(SYSTEM_PYTHON) -m venv --system-site-packages $(VENV); \
	fi

# pip runs only when requirements.txt differs from what the venv was last installed from.
requirements: venv
	@want="$$(sha256sum requirements.txt | cut -d' ' -f1)"; \
	if [[ "$$(cat $(VENV)/.requirements.sha256 2>/dev/null)" != "$$want" ]]; then \
	  echo "Installing requirements.txt into $(VENV)"; \
	  $(VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r requirements.txt; \
	  echo "$$want" > $(VENV)/.requirements.sha256; \
	fi

msgs: $(BUILD)/rosmc.stamp

# Standalone catkin build of the messages (devel space in build/devel), redone only when one
# of its inputs changed. A build/ configured for another checkout is removed first.
$(BUILD)/rosmc.stamp: $(BUILD_INPUTS) | apt
	@if [[ -f $(BUILD)/CMakeCache.txt ]] && ! grep -qx 'CMAKE_HOME_DIRECTORY:INTERNAL=$(CURDIR)' \
	     $(BUILD)/CMakeCache.txt; then echo "Removing $(BUILD)/ of another checkout"; rm -rf $(BUILD); fi
	@mkdir -p $(BUILD)
	@echo "Building messages into $(BUILD)/devel (log: $(BUILD)/rosmc-build.log)"
	@{ cmake -S . -B $(BUILD) -DPYTHON_EXECUTABLE=$(SYSTEM_PYTHON) && $(MAKE) -C $(BUILD); } \
	  > $(BUILD)/rosmc-build.log 2>&1 \
	  || { tail -n 40 $(BUILD)/rosmc-build.log; echo "Message build failed"; exit 1; }
	@touch $@

demo: setup
	$(IN_ENV) rosmc_demo $(if $(filter 1 yes true,$(GUI)),--gui) $(DEMO_ARGS)

# The committed sample recording the replay tests use (tools/record_sample.py says more).
sample: setup
	$(IN_ENV) python tools/record_sample.py

test: setup lint pytest

# Hypothesis profiles live in tests/conftest.py: `quick` (the default) and `thorough`.
test-thorough:
	HYPOTHESIS_PROFILE=thorough $(MAKE) test

# The suite must pass on a loaded machine; the busy processes stop whatever the outcome.
test-busy: setup
	$(IN_ENV) python tools/beside_busy.py --busy 2 -- $(MAKE) test

# pytest's own exit codes pass through: 5 (no test collected) fails the target.
# PYTEST_WORKERS processes share the test files (pytest-xdist, a file stays on one worker:
# module fixtures start once). Most tests wait on ROS processes, so two workers halve the
# time even on two cores; three were faster still but made the sim scenarios' timing
# flaky there. PYTEST_WORKERS=0 runs everything in this process. A worker that crashes is
# not replaced: the run fails at once with the crash's trace (a replaced worker could leave
# the run waiting for ever on the files it held).
PYTEST_WORKERS ?= 2
pytest: setup
	$(IN_ENV) python -m pytest $(if $(filter-out 0,$(PYTEST_WORKERS)),-n $(PYTEST_WORKERS) --dist loadfile --max-worker-restart 0) $(PYTEST_ARGS)

# Benchmarks print JSON figures; run_all collects them (one after another: they measure time).
bench: setup
	$(IN_ENV) python bench/run_all.py --docs $(if $(BENCH),--only $(BENCH))

lint: setup
	$(IN_ENV) ruff check .
	$(IN_ENV) ruff format --check .
	@echo "mypy --strict $(PACKAGES)"
	@$(IN_ENV) mypy --strict $(PACKAGES)
	tools/rosdep_offline.sh $(BUILD)/rosdep catkin_lint --strict --rosdistro debian .

format: setup
	$(IN_ENV) ruff check --fix .
	$(IN_ENV) ruff format .

clean:
	rm -rf $(BUILD) .mypy_cache .ruff_cache .pytest_cache
