# One entry point for users and CI. `make demo` and `make test` bootstrap what they need.
SHELL := /bin/bash
.SHELLFLAGS := -o pipefail -c
ROBOT ?= ur5
DRIVER ?=
DRIVER_OPTIONS ?=
HARDWARE_ARGS ?=
# The ROS master of a driver that runs already, e.g. on the robot's computer (README, Two computers).
MASTER ?=
# A cell file (or a name in mujoco_driver/config/cells): its arms in one world, demonstrated at once.
CELL ?=
BAG ?=
ENV := scripts/with_env
PYTEST_ARGS ?=
# Test files run on this many workers (pytest-xdist, whole files per worker); 0: one process, in order.
PYTEST_WORKERS ?= 2

.PHONY: setup build test test-unit lint demo bench robot check-robot param-tables clean

setup:
	@scripts/bootstrap setup

build:
	@scripts/bootstrap

# The simulations first, two workers; then the tests marked `compute` (minutes of pure computation: beside
# a simulation they starve it, and its timing is what the other tests judge), two workers; then those marked
# `alone`, one at a time. Exit 5 is "none selected".
test: build
	@$(ENV) python -m pytest $(if $(filter 0,$(PYTEST_WORKERS)),,-n $(PYTEST_WORKERS) --dist loadfile \
		-m "not alone and not compute") $(PYTEST_ARGS)
	@$(if $(filter 0,$(PYTEST_WORKERS)),true,$(ENV) python -m pytest -n $(PYTEST_WORKERS) --dist loadfile \
		-m compute $(PYTEST_ARGS) || [ $$? -eq 5 ])
	@$(if $(filter 0,$(PYTEST_WORKERS)),true,$(ENV) python -m pytest -m alone $(PYTEST_ARGS) || [ $$? -eq 5 ])

# The tests marked `unit` (tests/conftest.py: no ROS master, no simulator, no long computation), two workers.
test-unit: build
	@$(ENV) python -m pytest $(if $(filter 0,$(PYTEST_WORKERS)),,-n $(PYTEST_WORKERS)) -m unit $(PYTEST_ARGS)

lint: build
	@$(ENV) ruff check src tests scripts
	@$(ENV) mypy  # every package's library under src/ (mypy.ini)
	@$(ENV) catkin_lint -W2 --strict --offline src 2>&1 | grep -v rosdep

# The parameter tables of the package READMEs, regenerated from the parameter declarations.
param-tables: build
	@$(ENV) python -m compliant_common.schema_docs --write

demo: build
	@$(if $(CELL),$(ENV) python scripts/demo_cell --cell "$(CELL)",$(ENV) python scripts/demo --robot $(ROBOT) \
		$(if $(DRIVER),--driver $(DRIVER)) $(if $(DRIVER_OPTIONS),--driver-options "$(DRIVER_OPTIONS)") \
		$(if $(HARDWARE_ARGS),--hardware-args "$(HARDWARE_ARGS)") $(if $(BAG),--bag) \
		$(if $(MASTER),--master "$(MASTER)"))

# make robot NAME=<name> URDF=<path, or relative to example-robot-data's robots/> TIP=<flange link>
#   [BASE=<link>] [TOOL_MASS=<kg>] [TOOL_RPY=<roll,pitch,yaw>] [HELD=<joint=position,...>]
#   [DRIVER=<mujoco_driver profile name or YAML path>]: writes src/<name>_custom/ (hardware files for that
#   driver; none: a generic ros_control driver) and checks it. robot_setup's README: Add an arm.
robot: build
	@$(ENV) python -m robot_setup.generate --name "$(NAME)" --urdf "$(URDF)" --tip "$(TIP)" \
		$(if $(BASE),--base "$(BASE)") $(if $(TOOL_MASS),--tool-mass "$(TOOL_MASS)") \
		$(if $(TOOL_RPY),--tool-rpy="$(TOOL_RPY)") $(if $(HELD),--held "$(HELD)") \
		$(if $(DRIVER),--driver "$(DRIVER)") --src src
	@scripts/bootstrap >/dev/null

check-robot: build
	@$(ENV) python -m robot_setup.check --robot $(ROBOT)

bench: build
	@$(ENV) python scripts/bench_contact_control
	@$(ENV) python scripts/bench_jog_arm
	@$(ENV) python scripts/bench_sim_stack --robot $(ROBOT)
	@$(ENV) python scripts/bench_cell
	@$(ENV) python scripts/bench_allocations --robot $(ROBOT)

clean:
	rm -rf build devel .bootstrap/build.log
