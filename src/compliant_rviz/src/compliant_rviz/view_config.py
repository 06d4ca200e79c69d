"""A robot package's saved RViz view for a robot with a tf prefix (README, Namespaces): the fixed frame and
the robot model's links carry the prefix; topics are relative already, so RViz in the robot's namespace
reads the robot's own."""

from __future__ import annotations

import copy
from typing import Any

__all__ = ["prefixed_view"]

_FRAME_KEYS = ("Fixed Frame", "Reference Frame", "Target Frame")


def prefixed_view(view: dict[str, Any], prefix: str) -> dict[str, Any]:
    """A copy of `view` (a .rviz file's YAML) whose frames are `prefix/<frame>` and whose RobotModel
    displays look their links up under `prefix`; `view` itself is unchanged. An empty prefix: a plain copy."""
    out = copy.deepcopy(view)
    prefix = prefix.strip("/")
    if not prefix:
        return out

    def visit(node: Any) -> None:
        if isinstance(node, dict):
            for key, value in node.items():
                if key in _FRAME_KEYS and isinstance(value, str) and value and not value.startswith("<"):
                    node[key] = f"{prefix}/{value.lstrip('/')}"
                else:
                    visit(value)
            if node.get("Class") == "rviz/RobotModel":
                node["TF Prefix"] = prefix
        elif isinstance(node, list):
            for item in node:
                visit(item)

    visit(out)
    return out
