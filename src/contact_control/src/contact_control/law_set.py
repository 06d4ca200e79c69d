"""Six axis laws compiled once per request into what every cycle asks of them: which axes run, which check
a force jump, which follow a path, which the pressing guard or the minimum velocity apply to (no ROS here)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from contact_control.axes import LAW_FOLLOWER, LAW_FORCE_TRACKING, LAW_NONE, LAW_NORMAL, LAW_PATH
from contact_control.laws import AxisLaw

__all__ = ["LawSet"]

_NO_TRAVEL = (LAW_FOLLOWER, LAW_FORCE_TRACKING, LAW_NORMAL)  # no travel needed unless they have a max travel


@dataclass(frozen=True)
class LawSet:
    """Six laws (x, y, z, rx, ry, rz) and what follows from them; `of` builds one.

    Attributes:
        laws: the laws.
        types: each axis's law type.
        actions: per axis, the exceeded action (EXCEEDED_*) of its law; -1 without a force limit.
        active: the axes with a law.
        diff_axes: active axes whose force jump ends the move (their tuning's diff_max > 0).
        needs_travel: a law measures travel (spring, compliant move, a max travel): the move needs poses.
        floor: per axis, commands below the minimum velocity are zeroed (not for force tracking or a path).
        guarded: per axis, force tracking toward a nonzero target under the pressing guard (fast_guard).
        is_path: per axis, the path law.
        path_axes: the active axes on a path.
        watched: the active axes the oscillation watchdog watches (a path may turn on purpose).
        normal_axes: the active axes on the normal law (rx, ry).
        integrating: per axis, force tracking toward a nonzero target beside a path law: its integral
            term (force_integral) runs.
    """

    laws: tuple[AxisLaw, ...] = (AxisLaw(),) * 6
    types: tuple[int, ...] = (LAW_NONE,) * 6
    actions: tuple[int, ...] = (-1,) * 6
    active: tuple[int, ...] = ()
    diff_axes: tuple[int, ...] = ()
    needs_travel: bool = False
    floor: tuple[bool, ...] = (True,) * 6
    guarded: tuple[bool, ...] = (False,) * 6
    is_path: tuple[bool, ...] = (False,) * 6
    path_axes: tuple[int, ...] = ()
    watched: tuple[int, ...] = ()
    normal_axes: tuple[int, ...] = ()
    integrating: tuple[bool, ...] = (False,) * 6

    @classmethod
    def of(cls, laws: Sequence[AxisLaw], diff_max: Sequence[float], fast_guard: bool) -> LawSet:
        """The set of six `laws`; `diff_max` per axis (the force-jump limit, 0: none), `fast_guard` as the
        setting force_tracking_fast_guard."""
        laws = tuple(laws)
        active = tuple(i for i in range(6) if laws[i].law != LAW_NONE)
        is_path = tuple(law.law == LAW_PATH for law in laws)
        tracking = tuple(law.law == LAW_FORCE_TRACKING and law.target != 0.0 for law in laws)
        return cls(
            laws=laws,
            types=tuple(law.law for law in laws),
            actions=tuple(law.exceeded_action if law.law and law.force_limit > 0.0 else -1 for law in laws),
            active=active,
            diff_axes=tuple(i for i in active if diff_max[i] > 0.0),
            needs_travel=any(law.law not in _NO_TRAVEL or law.max_travel > 0.0 for law in laws if law.law),
            floor=tuple(law.law not in (LAW_FORCE_TRACKING, LAW_PATH, LAW_NORMAL) for law in laws),
            guarded=tuple(fast_guard and t for t in tracking),
            is_path=is_path,
            path_axes=tuple(i for i in active if is_path[i]),
            watched=tuple(i for i in active if not is_path[i]),
            normal_axes=tuple(i for i in active if laws[i].law == LAW_NORMAL),
            integrating=tuple(t and any(is_path) for t in tracking),
        )

    def with_law(self, axis: int, law: AxisLaw) -> LawSet:
        """The same set with `axis` running `law` of the same type (the watchdog's lowered gain)."""
        assert law.law == self.laws[axis].law, "with_law keeps the law type"
        laws = list(self.laws)
        laws[axis] = law
        return replace(self, laws=tuple(laws))
