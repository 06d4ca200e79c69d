# One entry point for users and CI. `make demo` and `make test` bootstrap what they need.
SHELL := /bin/bash
.SHELLFLAGS := -o pipefail -c
ROBOT ?= ur5
DRIVER ?=
ENV := scripts/with_env
PYTEST_ARGS ?=

.PHONY: setup build test lint demo bench clean

setup:
	@scripts/bootstrap setup

build:
	@scripts/bootstrap

test: build
	@$(ENV) python -m pytest $(PYTEST_ARGS)

lint: build
	@$(ENV) ruff check src tests scripts
	@$(ENV) catkin_lint -W2 --strict --offline src 2>&1 | grep -v rosdep

demo: build
	@$(ENV) python scripts/demo --robot $(ROBOT) $(if $(DRIVER),--driver $(DRIVER))

bench: build
	@$(ENV) python scripts/bench_contact_control
	@$(ENV) python scripts/bench_jog_arm
	@$(ENV) python scripts/bench_sim_stack --robot $(ROBOT)

clean:
	rm -rf build devel .bootstrap/build.log
