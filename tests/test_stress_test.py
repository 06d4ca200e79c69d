"""scripts/stress_test refuses bad arguments before it clones or spins anything (the runs themselves take the
whole suite's time: docs/measurements.md, *Test suite*)."""

from __future__ import annotations

import pathlib
import subprocess

import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "stress_test"


@pytest.mark.parametrize(("args", "said"), [
    (["--runs", "0"], "--runs needs a positive integer, got '0'"),
    (["--seed", "abc"], "--seed needs a number, got 'abc'"),
    (["--bogus"], "unknown argument '--bogus'"),
])
def test_bad_arguments_are_refused_with_the_reason(args, said):
    run = subprocess.run(["bash", str(SCRIPT), *args], capture_output=True, text=True, timeout=30,
                         check=False)
    assert run.returncode == 2 and said in run.stderr
    assert "[stress]" not in run.stdout  # nothing started
