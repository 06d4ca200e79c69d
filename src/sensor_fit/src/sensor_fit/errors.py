"""The package's one error: a recording that cannot be read or fitted."""

from __future__ import annotations

from compliant_common.errors import StackError

__all__ = ["SensorFitError"]


class SensorFitError(StackError):
    """The recording cannot be read or fitted; the message says why in one line."""
