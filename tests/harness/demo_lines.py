"""Figures read back from a demonstration's verdict line (thesis_demos' teach_and_replay): what the tests
of `make demo` and `make demo CELL=` judge."""

from __future__ import annotations

import re

__all__ = ["free_replays", "pressed_mean"]

_FREE = re.compile(r"free space 1x (\d+\.\d+) mm RMS, (\d+\.\d+) mm max; free space 2x (\d+\.\d+) mm RMS, "
                   r"(\d+\.\d+) mm max")
_PRESSED = re.compile(r"pressing[^;]* held (\d+\.\d+) N")


def free_replays(text: str) -> tuple[float, float, float, float] | None:
    """(RMS 1x, max 1x, RMS 2x, max 2x) [mm] of the free replays' path error, None if not in `text`."""
    said = _FREE.search(text)
    if said is None:
        return None
    rms_1x, max_1x, rms_2x, max_2x = (float(x) for x in said.groups())
    return rms_1x, max_1x, rms_2x, max_2x


def pressed_mean(text: str) -> float | None:
    """The pressed replay's mean force [N], None if not in `text`."""
    said = _PRESSED.search(text)
    return None if said is None else float(said.group(1))
