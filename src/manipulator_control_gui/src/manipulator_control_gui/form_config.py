"""The form description from `config/gui.yaml`: field units and ranges, law start values, presets.

Pure Python (no Qt, no rospy). Loaded once and checked, so a bad file fails at start-up naming the key.
"""

from __future__ import annotations

import math
import pathlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import yaml
from compliant_common.errors import StackError

__all__ = [
    "AXES",
    "AXIS_LABELS",
    "DEFAULT_CONFIG_PATH",
    "FIELDS",
    "LAWS",
    "LAW_FIELDS",
    "FieldSpec",
    "FormConfigError",
    "GuiConfig",
    "Preset",
    "is_angular",
    "load_config",
]

#: Axes of the control frame in message order.
AXES: tuple[str, ...] = ("x", "y", "z", "rx", "ry", "rz")
AXIS_LABELS: dict[str, str] = {axis: axis.upper() for axis in AXES}
#: Law names, in the order of the law box.
LAWS: tuple[str, ...] = ("none", "follower", "spring", "compliant_move")
#: Per-axis numeric fields, in column order.
FIELDS: tuple[str, ...] = ("damping", "stiffness", "velocity", "max_force", "max_deviation")
#: The fields each law uses (contact_control reads only these for an axis with that law).
LAW_FIELDS: dict[str, tuple[str, ...]] = {
    "none": (),
    "follower": ("damping", "max_force", "max_deviation"),
    "spring": ("damping", "stiffness", "max_force", "max_deviation"),
    "compliant_move": ("damping", "velocity", "max_force", "max_deviation"),
}

DEFAULT_CONFIG_PATH = pathlib.Path(__file__).resolve().parents[2] / "config" / "gui.yaml"


class FormConfigError(StackError):
    """The GUI configuration is malformed; `key` names the offending entry."""

    def __init__(self, key: str, message: str) -> None:
        super().__init__(f"gui config '{key}': {message}")
        self.key = key


def is_angular(axis: str) -> bool:
    """True for rx, ry, rz (torques, radians)."""
    return axis.startswith("r")


@dataclass(frozen=True)
class FieldSpec:
    """How one field is shown and bounded on one kind of axis."""

    label: str
    unit: str
    minimum: float
    maximum: float
    step: float
    decimals: int


@dataclass(frozen=True)
class Preset:
    """A named form: law and field values of the axes it sets (the others are `none`)."""

    name: str
    label: str
    axes: Mapping[str, Mapping[str, Any]]


@dataclass(frozen=True)
class GuiConfig:
    """The whole form description.

    Attributes:
        fields: (field, angular) -> FieldSpec.
        law_labels: law -> text of the law box.
        law_values: (law, angular) -> {field: start value}.
        presets: preset name -> Preset, in file order.
    """

    fields: Mapping[tuple[str, bool], FieldSpec]
    law_labels: Mapping[str, str]
    law_values: Mapping[tuple[str, bool], Mapping[str, float]]
    presets: Mapping[str, Preset]

    def spec(self, field: str, axis: str) -> FieldSpec:
        """The FieldSpec of `field` on `axis`."""
        return self.fields[(field, is_angular(axis))]

    def start_values(self, law: str, axis: str) -> Mapping[str, float]:
        """The values `law` starts with on `axis`."""
        return self.law_values[(law, is_angular(axis))]


def _mapping(key: str, value: Any) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise FormConfigError(key, f"expected a dictionary, got {value!r}")
    return value


def _number(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise FormConfigError(key, f"expected a finite number, got {value!r}")
    return float(value)


def _field_spec(key: str, label: str, raw: Any) -> FieldSpec:
    raw = _mapping(key, raw)
    for name in ("unit", "min", "max", "step", "decimals"):
        if name not in raw:
            raise FormConfigError(f"{key}.{name}", "missing")
    spec = FieldSpec(
        label=label,
        unit=str(raw["unit"]),
        minimum=_number(f"{key}.min", raw["min"]),
        maximum=_number(f"{key}.max", raw["max"]),
        step=_number(f"{key}.step", raw["step"]),
        decimals=int(_number(f"{key}.decimals", raw["decimals"])),
    )
    if spec.minimum >= spec.maximum:
        raise FormConfigError(key, f"min {spec.minimum} must be below max {spec.maximum}")
    if spec.step <= 0.0 or spec.decimals < 0:
        raise FormConfigError(key, "step must be > 0 and decimals >= 0")
    return spec


def _check_values(key: str, law: str, values: Mapping[str, Any], fields: Mapping) -> dict[str, float]:
    angular = key.endswith("angular")
    extra = set(values) - set(LAW_FIELDS[law])
    missing = set(LAW_FIELDS[law]) - set(values)
    if extra or missing:
        raise FormConfigError(
            key,
            f"law {law} uses exactly {list(LAW_FIELDS[law])}; "
            f"missing {sorted(missing)}, unknown {sorted(extra)}",
        )
    checked = {}
    for name, value in values.items():
        number = _number(f"{key}.{name}", value)
        spec = fields[(name, angular)]
        if not spec.minimum <= number <= spec.maximum:
            raise FormConfigError(f"{key}.{name}", f"{number} is outside [{spec.minimum}, {spec.maximum}]")
        checked[name] = number
    return checked


def _default_path() -> pathlib.Path:
    if DEFAULT_CONFIG_PATH.exists():  # source and devel space
        return DEFAULT_CONFIG_PATH
    import rospkg  # install space: the module is no longer next to config/

    return pathlib.Path(rospkg.RosPack().get_path("manipulator_control_gui")) / "config" / "gui.yaml"


def load_config(path: str | pathlib.Path | None = None) -> GuiConfig:
    """Loads and checks the form description.

    Args:
        path: the YAML file; None for the package's `config/gui.yaml`.

    Raises:
        FormConfigError: a key is missing, unknown, of the wrong type or out of its range.
        OSError: the file cannot be read.
    """
    path = pathlib.Path(path) if path else _default_path()
    data = _mapping(str(path), yaml.safe_load(path.read_text()))
    raw_fields = _mapping("fields", data.get("fields"))
    fields: dict[tuple[str, bool], FieldSpec] = {}
    for name in FIELDS:
        entry = _mapping(f"fields.{name}", raw_fields.get(name))
        label = str(entry.get("label", name))
        fields[(name, False)] = _field_spec(f"fields.{name}.linear", label, entry.get("linear"))
        fields[(name, True)] = _field_spec(f"fields.{name}.angular", label, entry.get("angular"))
    unknown = set(raw_fields) - set(FIELDS)
    if unknown:
        raise FormConfigError("fields", f"unknown fields {sorted(unknown)}; known: {list(FIELDS)}")

    raw_laws = _mapping("laws", data.get("laws"))
    if set(raw_laws) != set(LAWS):
        raise FormConfigError("laws", f"expected exactly {list(LAWS)}, got {sorted(raw_laws)}")
    law_labels: dict[str, str] = {}
    law_values: dict[tuple[str, bool], dict[str, float]] = {}
    for law in LAWS:
        entry = _mapping(f"laws.{law}", raw_laws[law])
        law_labels[law] = str(entry.get("label", law))
        for angular, kind in ((False, "linear"), (True, "angular")):
            key = f"laws.{law}.{kind}"
            law_values[(law, angular)] = _check_values(key, law, _mapping(key, entry.get(kind) or {}), fields)

    presets: dict[str, Preset] = {}
    for name, entry in _mapping("presets", data.get("presets") or {}).items():
        entry = _mapping(f"presets.{name}", entry)
        axes = _mapping(f"presets.{name}.axes", entry.get("axes"))
        for axis, values in axes.items():
            key = f"presets.{name}.axes.{axis}"
            if axis not in AXES:
                raise FormConfigError(key, f"unknown axis; known: {list(AXES)}")
            values = _mapping(key, values)
            if values.get("law") not in LAWS:
                raise FormConfigError(f"{key}.law",
                                      f"expected one of {list(LAWS)}, got {values.get('law')!r}")
            for field_name, value in values.items():
                if field_name != "law" and field_name not in LAW_FIELDS[values["law"]]:
                    raise FormConfigError(f"{key}.{field_name}", f"not a field of law {values['law']}")
                if field_name != "law":
                    _number(f"{key}.{field_name}", value)
        presets[name] = Preset(name, str(entry.get("label", name)), axes)
    return GuiConfig(fields, law_labels, law_values, presets)
