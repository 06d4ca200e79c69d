"""The one base of the stack's errors (see the package README): bad input, configuration or data, refused
with a message that names what to change. Each package's subclass says where it came from (jog_arm's
SettingsError, mujoco_driver's DriverParamError, ...); `except StackError` catches them all. It is a
ValueError, so code that caught ValueError before still does."""

from __future__ import annotations

__all__ = ["StackError"]


class StackError(ValueError):
    """Bad input or configuration, refused; the message says what and why."""
