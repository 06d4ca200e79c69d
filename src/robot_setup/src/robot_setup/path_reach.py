"""Can the arm run the curved demonstration's path as planned? Reach, jog_arm's singularity slow-down and
stop, and the lag that slow-down leaves behind the path's reference (pure: Pinocchio, no ROS).

The poses are the ones thesis_demos' curved_surface sends (its path over the nominal cylinder, from the
start pose's orientation) and the moves contact_tasks' follow_path makes before it: to the first pose's
standoff along the tool's axis, then the touch. Each is solved by IK from the one before (a jump over
0.5 rad is a branch switch: not a motion jog_arm makes). Along the path the tool's lag behind the
reference is integrated as jog_arm and the path law make it: the law asks v + k e, jog_arm scales that
down between `singularity_threshold` and `hard_stop_singularity_threshold` while the condition number
grows. With more joints than six the IK picks one of the arm's postures, not necessarily jog_arm's: the
verdict is for the path as planned from the start pose.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from compliant_common.typedefs import FloatArray
from contact_control.frames import quaternion_matrix
from contact_tasks.path_task import ARRIVE_TIME, CLEARANCE, MAX_LAG, PATH_STIFFNESS, PathGoal
from jog_arm.kinematics import ArmModel
from jog_arm.limits import singularity_scale
from thesis_demos.surfaces import cylinder_path

from robot_setup.analysis import condition_number, margins, solve_ik

__all__ = ["PathReach", "curved_path_reach", "predicted_lag"]

STEP = 0.005  # [m] between the path's poses checked
LAG_SHARE = 0.8  # a predicted lag above this share of the path's allowed lag is too close to call
AT_LIMIT = 0.01  # [rad] a joint this close to its limit stops there
_BRANCH_JUMP = 0.5  # [rad]


@dataclass(frozen=True)
class PathReach:
    """The verdict on a path.

    Attributes:
        reason: Why the arm cannot run it ("" if it can), in plain words.
        worst_condition: Largest condition number on the way (up to where it failed).
        lag: Largest predicted lag behind the path's reference [m].
        min_margin: Smallest joint-limit margin on the way [rad].
    """

    reason: str
    worst_condition: float
    lag: float
    min_margin: float


def _pose(row: Sequence[float]) -> pin.SE3:
    return pin.SE3(np.asarray(quaternion_matrix(*row[3:])), np.asarray(row[:3], dtype=float))


def _line(a: pin.SE3, b: pin.SE3, steps: int) -> list[pin.SE3]:
    turn, shift = pin.log3(b.rotation @ a.rotation.T), b.translation - a.translation
    return [pin.SE3(pin.exp3(turn * k / steps) @ a.rotation, a.translation + shift * (k / steps))
            for k in range(1, steps + 1)]


def predicted_lag(conditions: Sequence[float], step: float, speed: float, threshold: float,
                  hard_stop: float, arrive_time: float = ARRIVE_TIME) -> tuple[float, bool]:
    """Along a path of `conditions` every `step` m, run at `speed` [m/s]: (the largest lag of the tool
    behind the reference [m], whether the tool reaches the end within `arrive_time` s after it)."""
    n = len(conditions)
    length = step * (n - 1)
    dt = min(0.01, step / speed / 2.0)
    s_ref = s_tool = worst = 0.0
    t, end_t = 0.0, length / speed
    while t < end_t + arrive_time:
        i = min(int(s_tool / step), n - 2)
        toward = conditions[i + 1] > conditions[i]
        scale = singularity_scale(conditions[i], threshold, hard_stop, toward)
        s_ref = min(s_ref + speed * dt, length)
        lag = s_ref - s_tool
        s_tool += scale * (speed * (s_ref < length) + PATH_STIFFNESS * lag) * dt
        worst = max(worst, s_ref - s_tool)
        if s_tool >= length - 1e-4:
            return worst, True
        t += dt
    return worst, False


def curved_path_reach(arm: ArmModel, q0: FloatArray, top: Sequence[float], radius: float, length: float,
                      middle: float, speed: float, threshold: float, hard_stop: float,
                      length_scale: float, arrive_time: float = ARRIVE_TIME) -> PathReach:
    """The curved demonstration's path (`length` m over the nominal cylinder of `radius` whose highest
    point is `top`, centred `middle` rad from it toward +x, at `speed` m/s) from joint angles `q0`."""
    start = arm.frame_pose(np.asarray(q0, dtype=float), arm.tip_frame)
    rows = cylinder_path(top, radius, length, np.asarray(start.rotation), step=STEP, middle=middle)
    first = _pose(rows[0])
    axis = first.rotation[:, 2]
    standoff = PathGoal.standoff
    far = pin.SE3(first.rotation, first.translation - (standoff + CLEARANCE) * axis)
    near = pin.SE3(first.rotation, first.translation - standoff * axis)
    legs = [("the move to the path's start", _line(start, far, 20)),
            ("the approach along the tool's axis", _line(far, near, 10)),
            ("the touch", _line(near, first, 4)),
            ("the path", [_pose(r) for r in rows[1:]])]
    q = np.array(q0, dtype=float)
    worst, low = condition_number(arm, q, length_scale), float(np.min(margins(arm, q)))
    on_path = [worst]
    for leg, goals in legs:
        for k, goal in enumerate(goals):
            where = leg if leg != "the path" else f"the path, {(k + 1) * STEP:.3f} m along it"
            solved = solve_ik(arm, goal, q, iterations=100)
            if solved is None or float(np.max(np.abs(solved - q))) > _BRANCH_JUMP:
                return PathReach(f"{where}: the pose is out of reach from the start pose (a joint limit or a "
                                 "singularity; the tool's orientation follows the cylinder's normal)",
                                 worst, 0.0, low)
            q = solved
            c, left = condition_number(arm, q, length_scale), margins(arm, q)
            m = float(np.min(left))
            worst, low = max(worst, c), min(low, m)
            if c >= hard_stop:
                return PathReach(f"{where}: condition number {c:.1f}, at or above jog_arm's hard stop "
                                 f"{hard_stop:g} (hard_stop_singularity_threshold): the arm stops there",
                                 worst, 0.0, low)
            if m < AT_LIMIT:
                name = arm.joint_names[int(np.argmin(left))]
                return PathReach(f"{where}: {name} reaches its limit", worst, 0.0, low)
            if leg == "the touch":
                on_path = [c]
            elif leg == "the path":
                on_path.append(c)
    lag, arrives = predicted_lag(on_path, STEP, speed, threshold, hard_stop, arrive_time)
    if lag > LAG_SHARE * MAX_LAG or not arrives:
        return PathReach(f"the path: jog_arm slows near a singularity (condition number up to {worst:.1f}, "
                         f"slowing from {threshold:g}) and the tool would fall {lag * 1e3:.0f} mm behind the "
                         f"path's reference, of {MAX_LAG * 1e3:.0f} mm allowed", worst, lag, low)
    return PathReach("", worst, lag, low)
