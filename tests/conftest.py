"""Shared pytest set-up: import paths for the workspace's pure libraries, and the ROS fixtures."""

import pathlib
import re
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]

# Pure libraries are importable straight from src/ so unit tests need neither a build nor a master.
for _pkg_src in sorted(ROOT.glob("src/*/src")) + sorted(ROOT.glob("src/*/*/src")):
    if str(_pkg_src) not in sys.path:
        sys.path.insert(0, str(_pkg_src))
sys.path.insert(0, str(ROOT / "tests"))

pytest_plugins = ["harness.fixtures"]

from harness.launch import process_slot  # noqa: E402 (after the path set-up above)

# Tiers (pytest.ini): `e2e` for a test on a ROS master (the roscore fixture), a simulator (a module importing
# mujoco or mujoco_driver), minutes of computation (`compute`, `alone`) or marked `e2e` itself (a test that
# runs a simulation in a subprocess); `unit` for the rest (`make test-unit`).
_SIMULATOR = re.compile(r"^\s*(?:import|from)\s+mujoco", re.MULTILINE)


def pytest_collection_modifyitems(config, items):
    simulated: dict[str, bool] = {}
    for item in items:
        path = str(item.path)
        if path not in simulated:
            simulated[path] = bool(_SIMULATOR.search(item.path.read_text()))
        marked = any(item.get_closest_marker(name) is not None for name in ("e2e", "compute", "alone"))
        e2e = marked or "roscore" in getattr(item, "fixturenames", ()) or simulated[path]
        if not item.get_closest_marker("e2e"):
            item.add_marker(pytest.mark.e2e if e2e else pytest.mark.unit)


@pytest.fixture(autouse=True)
def _one_e2e_test_at_a_time(request):
    """An e2e test (not `compute`: those run in a phase of their own) holds the suite's process slot: two
    simulated stacks on a 2-core machine starved each other, and tests judged the load (docs/measurements.md,
    *Test suite*). Unit tests run beside it on the other worker."""
    node = request.node
    if node.get_closest_marker("e2e") is None or node.get_closest_marker("compute") is not None:
        yield
        return
    with process_slot():
        yield
