"""Health reports in diagnostic_msgs' terms, without ROS: levels, the documented thresholds, and a report's
worst level. The nodes build one `Report` per second off their control path (ros_diagnostics publishes it on
/diagnostics); the package README's "Health" section lists what each node reports.

Thresholds (documented there): an input's rate is OK from RATE_WARN of the expected rate, WARN from
RATE_ERROR, ERROR below it; an input older than its timeout is ERROR (the node has stopped the arm).
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["ERROR", "LEVEL_NAMES", "OK", "RATE_ERROR", "RATE_WARN", "STALE", "WARN", "Report", "rate_check",
           "summary"]

# diagnostic_msgs/DiagnosticStatus levels
OK, WARN, ERROR, STALE = 0, 1, 2, 3
LEVEL_NAMES = {OK: "OK", WARN: "WARN", ERROR: "ERROR", STALE: "STALE"}
RATE_WARN = 0.9  # an input below this fraction of its expected rate is WARN ...
RATE_ERROR = 0.5  # ... below this, ERROR


@dataclass
class Report:
    """One status: its level (the worst of its checks), the message (the worst checks' words) and values."""

    name: str
    level: int = OK
    message: str = ""
    values: list[tuple[str, str]] = field(default_factory=list)
    _words: list[tuple[int, str]] = field(default_factory=list, repr=False)

    def check(self, level: int, words: str) -> None:
        """A finding: the report's level is the worst one; its message joins the worst findings' words."""
        self._words.append((level, words))
        self.level = max(self.level, level)
        worst = [w for lvl, w in self._words if lvl == self.level and w]
        self.message = "; ".join(worst)

    def value(self, key: str, value: object) -> None:
        self.values.append((key, value if isinstance(value, str) else f"{value:.4g}"
                            if isinstance(value, float) else str(value)))


def rate_check(measured: float | None, expected: float, what: str) -> tuple[int, str]:
    """The level and words for an input at `measured` Hz (None: not measured yet) against `expected` Hz."""
    if measured is None:
        return WARN, f"{what}: rate not measured yet"
    if measured >= RATE_WARN * expected:
        return OK, ""
    level = WARN if measured >= RATE_ERROR * expected else ERROR
    return level, f"{what} at {measured:.4g} Hz, expected {expected:.4g} Hz"


def summary(statuses: list[tuple[int, str, str, list[tuple[str, str]]]], lowest: int = OK,
            detail: bool = False) -> str:
    """(level, name, message, values) statuses as rosdiagnostic prints them, worst first:
    `[ ERROR ] /contact_control_node - no wrench for 0.31 s` (with `detail`, the values below)."""
    lines = []
    for level, name, message, values in sorted(statuses, key=lambda s: (-s[0], s[1])):
        if level < lowest:
            continue
        lines.append(f"[ {LEVEL_NAMES.get(level, str(level))} ] {name} - {message}")
        if detail:
            lines += [f"    - {key}: {value}" for key, value in values]
    return "\n".join(lines)
