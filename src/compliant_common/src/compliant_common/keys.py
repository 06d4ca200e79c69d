"""Unknown parameter keys refuse start-up, naming the closest valid key: a typo (`global_max_forse`) must not
leave a node running on the default it meant to change."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = ["unknown_key_message"]


def unknown_key_message(key: str, known: Iterable[str], prefix: str = "") -> str:
    """"<prefix><key> is not a parameter: did you mean <prefix><closest>?" (or where to look)."""
    close = difflib.get_close_matches(key, sorted(set(known)), n=1, cutoff=0.6)
    hint = f"did you mean {prefix}{close[0]}?" if close else "see the package README for the parameters"
    return f"{prefix}{key} is not a parameter: {hint}"
