"""The four thesis demonstrations as data: laws per axis, simulated pushes, what to judge.

Pure: no rospy. Forces are in the robot's base frame [N]; velocities [m/s]; distances [m].
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["SCENARIOS", "AxisLaw", "Push", "Scenario", "by_name"]

AXES = ("x", "y", "z", "rx", "ry", "rz")
# cartesian_impedance_msgs/ControlLaw
NONE, FOLLOWER, SPRING, COMPLIANT_MOVE = 0, 1, 2, 3


@dataclass(frozen=True)
class AxisLaw:
    """One axis's law and the request fields it reads (0 means unused / no limit)."""

    law: int
    damping: float = 0.0  # b [N/(m/s)]
    stiffness: float = 0.0  # k [N/m]
    velocity: float = 0.0  # V_desired [m/s]
    force_limit: float = 0.0  # [N]
    torque_limit: float = 0.0  # [Nm], sent as max_ctrl_force.set.torque on the same axis letter
    max_travel: float = 0.0  # [m]


@dataclass(frozen=True)
class Push:
    """A simulated human push on the tool: `force` [N] in the base frame from `start` for `duration` [s]."""

    start: float
    duration: float
    force: tuple[float, float, float]

    @property
    def end(self) -> float:
        return self.start + self.duration


@dataclass(frozen=True)
class Scenario:
    """A demonstration: laws, pushes, how long to record, and the axes that matter."""

    name: str
    title: str
    laws: dict[str, AxisLaw]
    pushes: tuple[Push, ...] = ()
    duration: float = 6.0  # [s] recording time after the laws are set
    end_when_move_ends: bool = False  # stop recording early (after `settle`) once the move has ended
    settle: float = 1.0  # [s]
    controlled: tuple[str, ...] = field(default_factory=tuple)
    # max_ctrl_force.exceeded_action of the request (one for all axes with a force limit): stop, move_away or
    # gravity_compensation.
    exceeded_action: str = "stop"


# Thesis section 6.4, with the numbers it gives. Where it is silent: pushes of 5 N (follower) and
# 15 N (spring), V_desired -0.01 m/s (down, onto the obstacle: a usual approach speed for contact,
# and the contact force grows with it) and -0.05 m/s (X, toward the robot
# base, where both robots have 0.30 m of clear travel). The compliant move backs off from the obstacle once
# it stops (exceeded_action move_away): a position-controlled arm that stopped on contact otherwise keeps
# pressing on it with what it overshot (up to 9 N on a simulated arm).
SCENARIOS: tuple[Scenario, ...] = (
    Scenario(
        name="follower_z",
        title="Follower law on Z (b = 30)",
        laws={"z": AxisLaw(FOLLOWER, damping=30.0)},
        pushes=(Push(1.0, 0.8, (0.0, 0.0, 5.0)), Push(3.5, 0.5, (4.0, 4.0, 0.0))),
        duration=5.5,
        controlled=("z",),
    ),
    Scenario(
        name="compliant_move_z",
        title="Compliant move on Z toward an obstacle (max force 0.5 N, max torque 0.5 Nm), then move away",
        laws={
            "z": AxisLaw(
                COMPLIANT_MOVE,
                damping=30.0,
                velocity=-0.01,
                force_limit=0.5,
                torque_limit=0.5,
                max_travel=0.15,
            )
        },
        duration=11.0,
        end_when_move_ends=True,
        controlled=("z",),
        exceeded_action="move_away",
    ),
    Scenario(
        name="spring_x",
        title="Spring law on X (b = 30, k = 100)",
        laws={"x": AxisLaw(SPRING, damping=30.0, stiffness=100.0)},
        pushes=(Push(1.0, 3.0, (15.0, 0.0, 0.0)),),
        duration=7.0,
        controlled=("x",),
    ),
    Scenario(
        name="hybrid",
        title="Hybrid: compliant move on X (max path deviation 0.30 m) with spring on Z (b = 30, k = 100)",
        laws={
            "x": AxisLaw(
                COMPLIANT_MOVE,
                damping=30.0,
                velocity=-0.05,
                force_limit=0.5,
                torque_limit=0.5,
                max_travel=0.30,
            ),
            "z": AxisLaw(SPRING, damping=30.0, stiffness=100.0),
        },
        pushes=(Push(1.5, 2.0, (0.0, 0.0, 15.0)),),
        duration=9.0,
        end_when_move_ends=True,
        controlled=("x", "z"),
    ),
)


def by_name(names: list[str] | None) -> list[Scenario]:
    """The scenarios named (all when None or empty).

    Raises:
        KeyError: an unknown name.
    """
    if not names:
        return list(SCENARIOS)
    known = {s.name: s for s in SCENARIOS}
    missing = [n for n in names if n not in known]
    if missing:
        raise KeyError(f"unknown demo(s) {missing}; known: {sorted(known)}")
    return [known[n] for n in names]
