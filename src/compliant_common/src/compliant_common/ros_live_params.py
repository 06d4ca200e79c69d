"""Live tuning with dynamic_reconfigure (`rosrun dynamic_reconfigure dynparam set`, rqt_reconfigure) over a
node's own parameter schema: no .cfg file and no generated code, the description is built from the schema
(names, types, documentation) at start-up, so the two cannot disagree.

A change is handed to the node's `apply` (which validates the whole settings as at start-up and applies them
under its lock); a refused value keeps the old one: the server publishes the old configuration back and the
reason is logged and kept in `refused`. The description's bounds are open (no clamping): dynamic_reconfigure
would silently clamp an out-of-range value to its bound instead of refusing it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from types import SimpleNamespace
from typing import Any

import rospy

from compliant_common.schema import Schema

__all__ = ["LiveParams", "reconfigure_type"]

_TYPES = {"float": "double", "int": "int", "bool": "bool", "str": "str"}
_UNBOUNDED = {"double": (-float("inf"), float("inf")), "int": (-2**31, 2**31 - 1), "bool": (False, True),
              "str": ("", "")}
_CAST: dict[str, Callable[[Any], object]] = {"double": float, "int": int, "bool": bool, "str": str}


def reconfigure_type(schema: Schema, names: Iterable[str], values: Mapping[str, object]) -> SimpleNamespace:
    """What dynamic_reconfigure's Server reads from a generated `<Name>Config` module, for the schema's
    `names` with their current `values` as defaults.

    Raises:
        ValueError: a name the schema lacks, or of a type dynamic_reconfigure cannot carry.
    """
    parameters = []
    for name in names:
        if name not in schema:
            raise ValueError(f"{name}: not a parameter of this node")
        p = schema[name]
        kind = _TYPES.get(p.type)
        if kind is None:
            raise ValueError(f"{name}: type {p.type} cannot be tuned live")
        low, high = _UNBOUNDED[kind]
        unit = f" [{p.unit}]" if p.unit else ""
        parameters.append({"name": name, "type": kind, "default": _CAST[kind](values[name]), "level": 1,
                           "description": f"{p.doc}{unit}"[:200], "min": low, "max": high, "edit_method": "",
                           "srcline": 0, "srcfile": "", "cconsttype": "", "ctype": ""})
    description = {"name": "Default", "type": "", "state": True, "cstate": "true", "id": 0, "parent": 0,
                   "parameters": parameters, "groups": [], "srcline": 0, "srcfile": "", "class": "",
                   "parentclass": "", "parentname": "", "field": "", "upper": "DEFAULT", "lower": "groups"}
    return SimpleNamespace(
        config_description=description,
        defaults={p["name"]: p["default"] for p in parameters},
        min={p["name"]: p["min"] for p in parameters},
        max={p["name"]: p["max"] for p in parameters},
        level={p["name"]: 1 for p in parameters},
        type={p["name"]: p["type"] for p in parameters},
        all_level=1,
    )


class LiveParams:
    """A dynamic_reconfigure server for `names` of `schema` in `namespace` (the node's private one).

    Args:
        apply: Given the changed values (key -> value), applies them and returns '' or why they are refused
            (nothing changed then).
    """

    def __init__(self, schema: Schema, names: Iterable[str], values: Mapping[str, object],
                 apply: Callable[[dict[str, object]], str], namespace: str = "~") -> None:
        from dynamic_reconfigure.server import Server

        self._names = tuple(names)
        kind = reconfigure_type(schema, self._names, values)
        self._values = dict(kind.defaults)  # the current values, typed as dynamic_reconfigure carries them
        self._apply = apply
        self.refused = ""  # why the last change was refused ('' after an accepted one)
        # Resolved here: the Server joins "~" and "/" into "~/name", which rospy resolves as the global
        # "/name" (parameters of every node in one place, each reading the others').
        self._server = Server(kind, self._on_config, rospy.resolve_name(namespace).rstrip("/") + "/")

    def _on_config(self, config: dict[str, Any], _level: int) -> dict[str, Any]:
        changed = {n: config[n] for n in self._names if config[n] != self._values[n]}
        if not changed:
            return config
        reason = self._apply(changed)
        if reason:
            rospy.logwarn("%s: refused %s: %s (kept %s)", rospy.get_name(), changed, reason,
                          {n: self._values[n] for n in changed})
            self.refused = reason
            config.update({n: self._values[n] for n in changed})
            return config
        self.refused = ""
        self._values.update(changed)
        rospy.loginfo("%s: tuned %s", rospy.get_name(), changed)
        return config
