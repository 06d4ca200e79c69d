"""Shared pytest set-up: import paths for the workspace's pure libraries, and the ROS fixtures."""

import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]

# Pure libraries are importable straight from src/ so unit tests need neither a build nor a master.
for _pkg_src in sorted(ROOT.glob("src/*/src")) + sorted(ROOT.glob("src/*/*/src")):
    if str(_pkg_src) not in sys.path:
        sys.path.insert(0, str(_pkg_src))
sys.path.insert(0, str(ROOT / "tests"))

pytest_plugins = ["harness.fixtures"]


@pytest.hookimpl(trylast=True)  # after pytest-randomly's shuffle
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The order whole files go to the two workers (`make test`: --dist loadfile --no-loadscope-reorder):
    files marked `long_file` (minutes for a few tests) first, then the others by their number of tests, as
    xdist's own reorder does. xdist's order, by count alone, started the every-arm file (2 tests, 200 s) near
    the end, to run alone after everything else."""
    counts: dict[str, int] = {}
    for item in items:
        counts[item.nodeid.split("::")[0]] = counts.get(item.nodeid.split("::")[0], 0) + 1

    def key(item: pytest.Item) -> tuple[int, int]:
        path = item.nodeid.split("::")[0]
        return (0 if item.get_closest_marker("long_file") else 1, -counts[path])

    items.sort(key=key)  # stable: the shuffled order stays within a key
