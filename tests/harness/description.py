"""Running control_stack's make_description executable as roslaunch does (its own python3, or the shebang)."""

from __future__ import annotations

import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "src" / "control_stack" / "scripts" / "make_description"


def make_description(*args: str, python: str | None = sys.executable) -> subprocess.CompletedProcess:
    """Run the make_description executable (with ``python``, or through its shebang when None)."""
    cmd = ([python] if python else []) + [str(SCRIPT), *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=60, check=False)
