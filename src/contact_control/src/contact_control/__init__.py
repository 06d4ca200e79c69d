"""Compliant contact control (GCCF laws per Cartesian axis) as a pure library; `node` is the ROS adapter.

Public API: `ContactControl` (controller), `load_settings` (parameters), `validate_request` /
`fill_request` / `empty_request` (ConfigureForceControl mapping), `validate_laws_request` (ConfigureLaws),
`AxisLaw`, and the constants in `axes`.
"""

from contact_control.axes import AXES
from contact_control.controller import ContactControl
from contact_control.cycle import AxisState, CycleResult
from contact_control.laws import AxisLaw
from contact_control.params import ContactControlSettings, ParamError, load_settings
from contact_control.request import (
    RequestError,
    RequestLimits,
    empty_request,
    fill_request,
    validate_laws_request,
    validate_request,
)

__all__ = [
    "AXES",
    "AxisLaw",
    "AxisState",
    "ContactControl",
    "ContactControlSettings",
    "CycleResult",
    "ParamError",
    "RequestError",
    "RequestLimits",
    "empty_request",
    "fill_request",
    "load_settings",
    "validate_laws_request",
    "validate_request",
]
