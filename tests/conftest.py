"""Shared pytest set-up: import paths for the workspace's pure libraries, and the ROS fixtures."""

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]

# Pure libraries are importable straight from src/ so unit tests need neither a build nor a master.
for _pkg_src in sorted(ROOT.glob("src/*/src")) + sorted(ROOT.glob("src/*/*/src")):
    if str(_pkg_src) not in sys.path:
        sys.path.insert(0, str(_pkg_src))
sys.path.insert(0, str(ROOT / "tests"))

pytest_plugins = ["harness.fixtures"]
