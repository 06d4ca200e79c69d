"""Reach analysis of an arm with its tool: start pose search, tool-tip paths, condition numbers, margins.

Pure: Pinocchio through jog_arm's `ArmModel` (one angle per joint, continuous joints included), numpy.
No ROS master. Deterministic: the same description gives the same numbers (fixed grids and seeds).

Conventions (those of the robot packages and the demos):
  * the base frame is the URDF's root; the table top is its z = 0 plane; the demos work in front of the
    robot, along +X;
  * "tool pointing down" = the sensor/tool frame's z axis along -Z of the base, its x axis horizontal;
  * the condition number is jog_arm's: singular values of the tip Jacobian (LOCAL_WORLD_ALIGNED) with its
    linear rows divided by `singularity_length_scale` (0.4 m), largest over smallest.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from compliant_common.errors import StackError
from jog_arm.kinematics import ArmModel
from jog_arm.settings import JogSettings

__all__ = [
    "DOWN",
    "PathReport",
    "PoseReport",
    "StartPoseError",
    "analyse_pose",
    "condition_number",
    "estimate_reach",
    "find_start_pose",
    "lowest_joint",
    "margins",
    "sample_range",
    "solve_ik",
    "tip_path",
    "tool_down_heights",
]

# Tool pointing down: sensor x = +X, y = -Y, z = -Z of the base frame (the hand-written start poses).
DOWN = np.diag([1.0, -1.0, -1.0])
LENGTH_SCALE = JogSettings.singularity_length_scale  # [m] jog_arm's default
IK_TOLERANCE = 1e-6  # [m, rad] a pose counts as reached below this error
# With a free yaw, at a tool-down pose the 5-joint SO-100 has one joint fewer than constraints to first
# order (pan, lift, elbow, flex for the position and the axis; the roll turns about it), so the last microns
# converge slowly (6e-6 after 400 iterations). The start pose is written to 1e-4 rad anyway.
IK_TOLERANCE_FREE_YAW = 1e-4
# solve_ik gives up when STALL_ITERATIONS iterations left the error above STALL_ERROR and above STALL_RATIO of
# what it was (generating the UR3's and the Jaco2's packages gives the same files with and without this).
STALL_ITERATIONS, STALL_RATIO, STALL_ERROR = 20, 0.5, 1e-3
PATH_STEPS = 20
# A start pose is refused closer than this to a joint limit anywhere on the demos' motions [rad].
MIN_MARGIN = 0.15
# Every joint origin but the first stays this high over the table (z = 0) at the start pose [m]: no elbow
# reaching under the table top.
MIN_JOINT_HEIGHT = 0.05


# StartPoseError says this when no posture points the tool down where the demos start (smaller demos: neither)
NO_TOOL_DOWN = "no tool-down IK solution in front of the robot"


class StartPoseError(StackError, RuntimeError):
    """No start pose satisfies the demands (the message says which were tried and why they failed)."""


def condition_number(arm: ArmModel, q: np.ndarray, length_scale: float = LENGTH_SCALE) -> float:
    """jog_arm's condition number of the tip Jacobian at `q` (linear rows divided by `length_scale`)."""
    jac = arm.jacobian(np.asarray(q, dtype=float)).copy()
    jac[:3] /= length_scale
    sv = np.linalg.svd(jac, compute_uv=False)
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf


def margins(arm: ArmModel, q: np.ndarray) -> np.ndarray:
    """Distance of each joint to its nearer position limit [rad]; inf for unbounded (continuous) joints. A
    prismatic joint's metres count as radians at LENGTH_SCALE (MIN_MARGIN's 0.15 rad is 6 cm of a rail)."""
    q = np.asarray(q, dtype=float)
    return np.minimum(q - arm.lower, arm.upper - q) / np.where(arm.prismatic, LENGTH_SCALE, 1.0)


def lowest_joint(arm: ArmModel, q: np.ndarray) -> float:
    """Height [m] of the lowest joint origin after the first (which sits on the base), base frame."""
    arm.frame_pose(np.asarray(q, dtype=float), arm.tip_frame)  # forward kinematics into arm.data
    return float(min(arm.data.oMi[j].translation[2] for j in range(2, arm.model.njoints)))


def _pose_error(arm: ArmModel, q: np.ndarray, goal: pin.SE3) -> np.ndarray:
    """(position error, rotation error) in base axes, 6-vector, goal minus current; with fewer than six
    joints the rotation about the goal's tool axis is free (`_error`)."""
    return _error(arm.frame_pose(q, arm.tip_frame), goal, arm.nv < 6)


def _error(tip: pin.SE3, goal: pin.SE3, free_yaw: bool) -> np.ndarray:
    """Goal minus `tip`: translation, then rotation vector. `free_yaw`: only the rotation that turns the tool
    axis (z) onto the goal's, so the turn about that axis is left free (an arm with fewer than six joints
    points its tool down with whatever yaw its joints give)."""
    if not free_yaw:
        return np.concatenate([goal.translation - tip.translation, pin.log3(goal.rotation @ tip.rotation.T)])
    now, want = tip.rotation[:, 2], goal.rotation[:, 2]
    axis = np.cross(now, want)
    sin, cos = float(np.linalg.norm(axis)), float(now @ want)
    angle = math.atan2(sin, cos)
    rot = axis * (angle / sin) if sin > 1e-12 else np.zeros(3)
    return np.concatenate([goal.translation - tip.translation, rot])


def solve_ik(
    arm: ArmModel, goal: pin.SE3, seed: np.ndarray, iterations: int = 200, limit_margin: float = 0.0
) -> np.ndarray | None:
    """Damped least-squares IK of the tool tip to `goal`, joints kept `limit_margin` inside their limits.

    With fewer than six joints the tool's turn about its axis (z) is free: position and tool axis only.

    Returns:
        The joint angles (one per joint, model order), or None if it did not converge.
    """
    q = np.array(seed, dtype=float)
    lo, hi = arm.lower + limit_margin, arm.upper - limit_margin
    earlier = math.inf
    free_yaw = arm.nv < 6
    tolerance = IK_TOLERANCE_FREE_YAW if free_yaw else IK_TOLERANCE
    if free_yaw:  # the Jacobian's rotation rows without the turn about the goal's tool axis
        axis = goal.rotation[:, 2]
        plane = np.eye(3) - np.outer(axis, axis)
    for i in range(iterations):
        jac = arm.jacobian(q)  # also places the tip frame: one kinematics pass per iteration
        err = _error(arm.data.oMf[arm.tip_id], goal, free_yaw)
        if free_yaw:
            jac[3:] = plane @ jac[3:]
        norm = float(np.linalg.norm(err))
        if norm < tolerance:
            return q
        if i % STALL_ITERATIONS == 0:
            # Stuck (against a limit, or at a goal out of reach): a converging solve gains far more than
            # this in STALL_ITERATIONS; most of the start pose search's time went on such hopeless seeds.
            if norm > STALL_RATIO * earlier and norm > STALL_ERROR:
                return None
            earlier = norm
        damping = 1e-6 + 1e-3 * min(1.0, norm)
        step = jac.T @ np.linalg.solve(jac @ jac.T + damping * _EYE6, err)
        biggest = float(np.max(np.abs(step)))
        if biggest > 0.5:  # far from the goal: no wild jumps across branches
            step *= 0.5 / biggest
        q = np.minimum(np.maximum(q + step, lo), hi)
    return q if float(np.linalg.norm(_pose_error(arm, q, goal))) < tolerance else None


_EYE6 = np.eye(6)


@dataclass(frozen=True)
class PathReport:
    """A straight tool-tip motion from the start pose, orientation held.

    Attributes:
        offset: The displacement [m], base axes.
        reachable: Every step was reached (no joint limit or singularity in the way).
        worst_condition: Largest condition number on the way.
        min_margin: Smallest distance of a joint to its limits on the way [rad].
        contact: Bodies that touch on the way (self-collision or the table), empty if none or unchecked.
    """

    offset: tuple[float, ...]  # (x, y, z)
    reachable: bool
    worst_condition: float
    min_margin: float
    contact: str = ""


def tip_path(
    arm: ArmModel, q0: np.ndarray, offset: Sequence[float], steps: int = PATH_STEPS
) -> tuple[list[np.ndarray], bool]:
    """Joint configurations moving the tip in a straight line by `offset` [m], orientation held.

    Returns:
        (the configurations reached, one per step; True if every step was reached).
    """
    start = arm.frame_pose(np.asarray(q0, dtype=float), arm.tip_frame).copy()
    q = np.array(q0, dtype=float)
    path: list[np.ndarray] = []
    for k in range(1, steps + 1):
        goal = pin.SE3(start.rotation, start.translation + np.asarray(offset, dtype=float) * k / steps)
        solved = solve_ik(arm, goal, q, iterations=50)
        if solved is None or float(np.max(np.abs(solved - q))) > 0.5:  # a jump = a branch switch
            return path, False
        q = solved
        path.append(q.copy())
    return path, True


@dataclass(frozen=True)
class PoseReport:
    """A start pose and what the demos' motions do from it.

    Attributes:
        q: Joint angles [rad], model order.
        joint_names: Model order.
        tip: Tool tip position [m], base frame.
        condition: Condition number at the pose.
        margins: Per joint distance to the limits at the pose [rad] (inf: continuous).
        paths: Per demonstration, its motions.
        contact: Bodies touching at the pose itself (empty: none or unchecked).
    """

    q: np.ndarray
    joint_names: tuple[str, ...]
    tip: np.ndarray
    condition: float
    margins: np.ndarray
    paths: dict[str, list[PathReport]] = field(default_factory=dict)
    contact: str = ""

    @property
    def reachable(self) -> bool:
        return all(p.reachable for reports in self.paths.values() for p in reports)

    @property
    def collision_free(self) -> bool:
        return not self.contact and not any(p.contact for r in self.paths.values() for p in r)

    @property
    def worst_condition(self) -> float:
        return max([self.condition] + [p.worst_condition for r in self.paths.values() for p in r])

    @property
    def min_margin(self) -> float:
        on_paths = [p.min_margin for r in self.paths.values() for p in r]
        return float(min([float(np.min(self.margins)), *on_paths]))

    def problems(self, hard_stop: float | None = None) -> list[str]:
        """What is wrong with this pose for the demos, in plain words (empty: nothing)."""
        out = [f"start pose: {self.contact} touch"] if self.contact else []
        for demo, reports in self.paths.items():
            for p in reports:
                dx, dy, dz = p.offset
                where = f"{demo}: the tool-tip motion ({dx:+.3f}, {dy:+.3f}, {dz:+.3f}) m"
                if not p.reachable:
                    out.append(f"{where} is not reachable from the start pose (joint limit or singularity)")
                elif p.contact:
                    out.append(f"{where} makes {p.contact} touch (the arm would hit itself or the table)")
                elif hard_stop is not None and p.worst_condition >= hard_stop:
                    out.append(
                        f"{where} reaches condition number {p.worst_condition:.1f}, at or above jog_arm's "
                        f"hard stop {hard_stop:g}"
                    )
                elif p.min_margin < MIN_MARGIN:
                    out.append(
                        f"{where} comes {p.min_margin:.2f} rad from a joint limit (at least "
                        f"{MIN_MARGIN} rad wanted)"
                    )
        return out


def analyse_pose(
    arm: ArmModel, q0: np.ndarray, motions: Mapping[str, Sequence[Sequence[float]]],
    length_scale: float = LENGTH_SCALE, contacts: Callable[[np.ndarray], list[str]] | None = None,
) -> PoseReport:
    """Condition numbers, joint-limit margins and (with `contacts`) collisions at `q0` and along each
    demonstration's motions (every fifth step and the last)."""
    q0 = np.asarray(q0, dtype=float)
    paths: dict[str, list[PathReport]] = {}
    for demo, offsets in motions.items():
        paths[demo] = []
        for offset in offsets:
            path, ok = tip_path(arm, q0, offset)
            conds = [condition_number(arm, q, length_scale) for q in path] or [math.inf]
            mins = [float(np.min(margins(arm, q))) for q in path] or [-math.inf]
            touching: list[str] = []
            if contacts is not None:
                for q in path[4::5] + path[-1:]:
                    touching += [c for c in contacts(q) if c not in touching]
            paths[demo].append(
                PathReport(tuple(float(v) for v in offset), ok, max(conds), min(mins), ", ".join(touching))
            )
    return PoseReport(
        q=q0,
        joint_names=arm.joint_names,
        tip=arm.frame_pose(q0, arm.tip_frame).translation.copy(),
        condition=condition_number(arm, q0, length_scale),
        margins=margins(arm, q0),
        paths=paths,
        contact=", ".join(contacts(q0)) if contacts is not None else "",
    )


def sample_range(arm: ArmModel) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's limits, +-pi for an unbounded one: where pseudo-random postures are drawn."""
    return (np.where(np.isfinite(arm.lower), arm.lower, -math.pi),
            np.where(np.isfinite(arm.upper), arm.upper, math.pi))


def _seeds(arm: ArmModel, count: int = 6) -> list[np.ndarray]:
    """Deterministic IK seeds: mid-range, then fixed pseudo-random configurations within the limits."""
    lo, hi = sample_range(arm)
    rng = np.random.default_rng(0)
    seeds = [(lo + hi) / 2.0]
    seeds += [lo + (hi - lo) * (0.15 + 0.7 * rng.random(arm.nv)) for _ in range(count - 1)]
    return seeds


def _off_centre(arm: ArmModel, q: np.ndarray) -> float:
    """Mean distance of the joints from the middle of their ranges, as a fraction of the half range."""
    lo, hi = sample_range(arm)
    return float(np.mean(np.abs(q - (lo + hi) / 2.0) / ((hi - lo) / 2.0)))


REPORTED = 20  # candidates analysed in full to say why no start pose was found


def _hopeless(
    arm: ArmModel, q: np.ndarray, motions: Mapping[str, Sequence[Sequence[float]]], length_scale: float,
    contacts: Callable[[np.ndarray], list[str]] | None, worst_allowed: float,
) -> bool:
    """Whether a start pose cannot be the one chosen, found before its full analysis: a motion unreachable,
    too close to a joint limit, touching, or conditioned at `worst_allowed` or worse (the score it would need
    to beat the best so far). Stops at the first such motion: most candidates fail on their first one."""
    for offsets in motions.values():
        for offset in offsets:
            path, ok = tip_path(arm, q, offset)
            if not ok:
                return True
            for step in path:
                if condition_number(arm, step, length_scale) >= worst_allowed:
                    return True
                if float(np.min(margins(arm, step))) < MIN_MARGIN:
                    return True
            if contacts is not None and any(contacts(step) for step in path[4::5] + path[-1:]):
                return True
    return False


def estimate_reach(arm: ArmModel, samples: int = 2000) -> float:
    """How far the tool tip gets from the first joint's axis [m]: the largest horizontal distance of the
    tip from the base's z axis over fixed pseudo-random configurations (a lower bound of the true reach)."""
    rng = np.random.default_rng(1)
    lo, hi = sample_range(arm)
    best = 0.0
    for _ in range(samples):
        q = lo + (hi - lo) * rng.random(arm.nv)
        p = arm.frame_pose(q, arm.tip_frame).translation
        best = max(best, float(math.hypot(p[0], p[1])))
    return best


def tool_down_heights(arm: ArmModel, reach: float, samples: int = 4000) -> list[float]:
    """Heights [m] where the tool can point down in front of the robot: the 50th, 65th, 80th and 95th
    percentiles of the tool tip's height over fixed pseudo-random configurations whose tool points within 25
    degrees of down, more than 0.3 of the reach in front (empty: none found). For an arm standing high (on a
    torso), whose tool-down workspace is not where a table-mounted arm's is."""
    rng = np.random.default_rng(2)
    lo, hi = sample_range(arm)
    found = []
    for _ in range(samples):
        q = lo + (hi - lo) * rng.random(arm.nv)
        pose = arm.frame_pose(q, arm.tip_frame)
        if pose.rotation[2, 2] < -0.9 and pose.translation[0] > 0.3 * reach:
            found.append(float(pose.translation[2]))
    if not found:
        return []
    return [float(np.percentile(found, p)) for p in (50, 65, 80, 95)]


def _rot_z(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def find_start_pose(
    arm: ArmModel,
    reach: float,
    motions_for: Callable[[np.ndarray], Mapping[str, Sequence[Sequence[float]]]],
    length_scale: float = LENGTH_SCALE,
    max_condition: float = 25.0,
    heights: Sequence[float] | None = None,
    contacts: Callable[[np.ndarray], list[str]] | None = None,
) -> PoseReport:
    """The best start pose: tool pointing down in front of the robot, the demos' motions reachable.

    Candidates are tool-tip positions on a fixed grid (x from 0.35 to 0.7 of `reach` along +X, y within
    +-0.15 of it, heights as given, default 0.2 to 0.45 of it) and tool yaws of 0, 90, 180, -90 degrees; every
    IK solution from fixed seeds is analysed along `motions_for(tip)` (the demos' displacements, which may
    depend on the height). Kept: all motions reachable, never closer than MIN_MARGIN to a joint limit, worst
    condition number below `max_condition`. Chosen: the lowest worst condition number, ties to larger margins.

    Raises:
        StartPoseError: No candidate passes; the message gives the closest one's problems.
    """
    heights = list(heights) if heights is not None else [reach * f for f in (0.2, 0.28, 0.36, 0.45)]
    xs = [reach * f for f in (0.45, 0.55, 0.4, 0.62, 0.35, 0.7)]
    ys = [0.0, 0.08 * reach, -0.08 * reach, 0.15 * reach, -0.15 * reach]
    yaws = [0.0, math.pi / 2, math.pi, -math.pi / 2] if arm.nv >= 6 else [0.0]  # fewer: yaw is free
    seeds = _seeds(arm)
    best: tuple[float, PoseReport] | None = None
    closest: tuple[float, PoseReport] | None = None
    rejected: list[tuple[np.ndarray, np.ndarray]] = []  # (q, tip) of candidates _hopeless turned down
    for z in heights:
        # Every IK solution at this height with the least score its analysis could give (the worst condition
        # number is at least the start's, the margin term at least -0.5); analysed best bound first, until no
        # bound can beat the best score: the same choice as analysing them all, at a fraction of the cost.
        candidates: list[tuple[float, int, np.ndarray, np.ndarray]] = []
        for x in xs:
            for y in ys:
                for yaw in yaws:
                    goal = pin.SE3(_rot_z(yaw) @ DOWN, np.array([x, y, z]))
                    found: list[np.ndarray] = []
                    for seed in seeds:
                        q = solve_ik(arm, goal, seed, limit_margin=MIN_MARGIN)
                        if q is None or any(np.allclose(q, f, atol=1e-3) for f in found):
                            continue
                        found.append(q)
                    for q in found:
                        condition = condition_number(arm, q, length_scale)
                        if condition >= max_condition or lowest_joint(arm, q) < MIN_JOINT_HEIGHT:
                            continue
                        bound = condition + 2.0 * _off_centre(arm, q) - 0.5
                        candidates.append((bound, len(candidates), q, np.array([x, y, z])))
        candidates.sort(key=lambda c: (c[0], c[1]))
        for bound, _, q, tip in candidates:
            if best is not None and bound >= best[0] - 1e-9:
                break
            if contacts is not None and contacts(q):
                continue
            # The worst condition number that could still beat the best score (whose margin term is >= -0.5).
            limit = math.inf if best is None else best[0] - 1e-9 - 2.0 * _off_centre(arm, q) + 0.5
            if _hopeless(arm, q, motions_for(tip), length_scale, contacts, min(max_condition, limit)):
                rejected.append((q, tip))
                continue
            report = analyse_pose(arm, q, motions_for(tip), length_scale, contacts)
            worst = report.worst_condition
            # Lowest condition number first; then joints near the middle of their ranges (a familiar posture
            # rather than one wound round a +-2 pi joint) and wider margins.
            score = worst + 2.0 * _off_centre(arm, q) - 0.5 * min(report.min_margin, 1.0)
            usable = report.reachable and report.collision_free and report.min_margin >= MIN_MARGIN
            if usable and worst < max_condition:
                if best is None or score < best[0] - 1e-9:
                    best = (score, report)
            elif closest is None or score < closest[0]:
                closest = (score, report)
        if best is not None and z >= heights[min(1, len(heights) - 1)]:
            break  # a good pose at a moderate height: higher ones only shorten the follower's room
    if best is None:
        for q, tip in rejected[:REPORTED]:  # the closest candidates' problems, for the message
            report = analyse_pose(arm, q, motions_for(tip), length_scale, contacts)
            score = report.worst_condition + 2.0 * _off_centre(arm, q) - 0.5 * min(report.min_margin, 1.0)
            if closest is None or score < closest[0]:
                closest = (score, report)
        detail = "; ".join(closest[1].problems()) if closest else NO_TOOL_DOWN
        raise StartPoseError(
            "no start pose with the tool pointing down lets the demos' motions run (reach estimate "
            f"{reach:.2f} m, "
            f"condition number below {max_condition:g}, {MIN_MARGIN} rad from every joint limit): {detail}"
        )
    return best[1]
