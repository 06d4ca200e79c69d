"""Fixtures for control_stack's tests."""

from __future__ import annotations

import pytest
from harness.description import make_description


@pytest.fixture(scope="session")
def run_make_description():
    """The make_description runner (a fixture, so test modules need not import the harness)."""
    return make_description
