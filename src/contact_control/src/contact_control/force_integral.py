"""Force tracking's integral action beside a path law (README, *Force tracking*, "A moving surface"; no ROS).

Force tracking's V = (F - F_target) / b is a proportional law: a surface that moves away from the tool at
r m/s is followed with the force short of its target by b r. Beside a path law that is the usual case, not
an exception: sliding along a curved part with the tool's axis a degree off the true normal (a sensor's slow
drift of 0.2 N, as fitted for the UR e-series' sensor in mujoco_driver's ur_robot_driver profile, tilts the
read normal that much at 10 N) carries the tool off the part at v sin(angle), 0.4 mm/s at 20 mm/s, and at
b = 2000 the force settles 0.8 N short, less the pressing the fast guard vetoes on the raw force's spikes.
The integral term adds (1 / (b T_i)) times the force error's integral, so the error decays with the time
constant T_i instead of staying.

It integrates the error outside the law's deadband, only in contact (F past the contact fraction of its
target): out of contact the law approaches at its approach speed and the term restarts from zero, so a
lift-off never winds it up. Its size is capped at the law's approach speed: what it adds is a slow
correction, never a second approach.
"""

from __future__ import annotations

from contact_control.law_set import LawSet
from contact_control.laws import AxisLaw, guard_pressing, short_of_contact
from contact_control.params import AxisTuning

__all__ = ["ForceIntegral"]


class ForceIntegral:
    """The integral term of each force-tracking axis of a move beside a path law (`LawSet.integrating`);
    `adopt` when laws are set."""

    def __init__(self) -> None:
        self._term = [0.0] * 6

    def adopt(self, laws: LawSet, fresh: bool) -> None:
        """New laws: every term from zero for a new move (`fresh`), else those of the axes that stopped
        integrating (an axis that keeps force tracking beside a path keeps its term: bumpless)."""
        for i in range(6):
            if fresh or not laws.integrating[i]:
                self._term[i] = 0.0

    def velocity(self, axis: int, laws: LawSet, tuning: AxisTuning, v: float, force: float, fast: float,
                 dt: float) -> float:
        """Force tracking's law velocity `v` of `axis` with what the move adds to it: this term beside a path
        (`step`, the filtered `force`), then the pressing guard on the unfiltered `fast` force."""
        law = laws.laws[axis]
        if laws.integrating[axis]:
            v += self.step(axis, law, tuning, force, dt)
        return guard_pressing(law, tuning, v, fast) if laws.guarded[axis] else v

    def step(self, axis: int, law: AxisLaw, tuning: AxisTuning, force: float, dt: float) -> float:
        """The term's velocity this cycle [m/s or rad/s] for the filtered `force` of `axis`, `dt` [s] since
        the last cycle (0 while `tuning.track_integral_time` is 0)."""
        time, target = tuning.track_integral_time, law.target
        if time <= 0.0 or short_of_contact(target, tuning.contact_fraction, force):
            self._term[axis] = 0.0
            return 0.0
        error, band = force - target, tuning.track_deadband
        if -band <= error <= band:
            return self._term[axis]
        error -= band if error > 0.0 else -band  # the law's deadband: no hunting on noise
        cap = law.velocity if law.velocity > 0.0 else tuning.default_velocity
        term = self._term[axis] + error * dt / (law.damping * time)
        term = cap if term > cap else -cap if term < -cap else term
        self._term[axis] = term
        return term
