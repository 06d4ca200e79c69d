"""RViz markers as the tests read them (compliant_rviz)."""

from __future__ import annotations


def named(array, ns: str):
    """The marker of namespace `ns` that a MarkerArray adds (None: absent, deleted, or no array yet)."""
    for m in array.markers if array is not None else ():
        if m.ns == ns:
            return m if m.action == m.ADD else None
    return None
