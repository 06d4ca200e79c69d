"""Where the tool goes on the flange and where the arm starts: the start pose search over mountings (straight,
the user's `TOOL_RPY`, or adapter angles), for `robot_setup.generate` (robot_setup README, "Add an arm").

No ROS here. Deterministic: fixed angles, grids and seeds.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from control_stack.description import ToolSpec, build_description
from jog_arm.kinematics import ArmModel, KinematicsError

from robot_setup.analysis import (
    NO_TOOL_DOWN,
    PoseReport,
    StartPoseError,
    find_start_pose,
    sample_range,
    tool_down_heights,
)
from robot_setup.collisions import CollisionChecker
from robot_setup.plan import GeneratorError, RobotSpec

__all__ = ["ADAPTERS", "POOR_CONDITION", "TOOL_COM", "TOOL_SIZE", "Mounter", "Mounting", "NoMountingError"]

TOOL_SIZE = (0.03, 0.12)  # [m] cylinder radius, length: the hand-written packages' tool
TOOL_COM = (0.0, 0.0, 0.05)  # [m] in the sensor frame
# Adapter angles tried when the straight mounting cannot point the tool down (roll, pitch, yaw of the sensor
# on the flange) [rad]: right-angle and 45-degree brackets about the flange's x and y axes.
ADAPTERS = tuple(
    (r * math.pi / 4.0, p * math.pi / 4.0, 0.0) for r, p in
    ((2, 0), (-2, 0), (0, 2), (0, -2), (1, 0), (-1, 0), (0, 1), (0, -1))
)
# A straight mounting whose demos reach a worse condition number than this has the adapters tried too (the
# UR3's ee_link, whose z is across the flange: 21.6, its touching on the block overshot to 26 N and tripped
# the 25 N global limit; the UR3 on tool0 13.2, the Jaco2 5.4, left as they were).
POOR_CONDITION = 15.0

Contacts = Callable[[Sequence[float] | np.ndarray], list[str]]
RPY = tuple[float, float, float]


class NoMountingError(GeneratorError):
    """No mounting has a start pose for these motions; `hopeless`: smaller motions cannot help either (in
    every mounting the tool touches the arm in every posture, or cannot point down in front of the robot)."""

    def __init__(self, message: str, hopeless: bool) -> None:
        super().__init__(message)
        self.hopeless = hopeless


@dataclass(frozen=True)
class Mounting:
    """A mounting with its start pose.

    Attributes:
        rpy: The sensor's mounting on the flange (roll, pitch, yaw) [rad].
        urdf_xml: The description with the tool mounted so.
        arm: Its jog_arm model.
        contacts: Its collision check (bodies touching at a posture).
        found: The start pose and the demos' motions from it.
        adapter: Why make robot chose an adapter, in words ("" for straight or the user's TOOL_RPY).
    """

    rpy: RPY
    urdf_xml: str
    arm: ArmModel
    contacts: Contacts
    found: PoseReport
    adapter: str = ""


def mid_range(arm: ArmModel) -> np.ndarray:
    """The middle of each bounded joint's range, 0 for an unbounded one (a posture inside every limit)."""
    bounded = np.isfinite(arm.lower) & np.isfinite(arm.upper)
    return (np.where(bounded, arm.lower, 0.0) + np.where(bounded, arm.upper, 0.0)) / 2.0


def _heights(arm: ArmModel, reach: float, gap: float) -> list[float]:
    """The start pose search's tool-tip heights: over the table (the URDF root's z = 0 plane) by a fraction of
    the reach; for an arm whose first joint stands higher than half its reach over the table (on a torso),
    where its tool can point down."""
    mid = mid_range(arm)
    first = arm.joint_names[0]
    shoulder = float(arm.frame_pose(mid, first).translation[2]) if arm.has_frame(first) else 0.0
    fractions = [reach * f for f in (0.2, 0.28, 0.36, 0.45)]
    return [h for h in (fractions if shoulder < 0.5 * reach else tool_down_heights(arm, reach))
            if h >= gap + 0.04]


def _tool_stuck(arm: ArmModel, contacts: Contacts) -> str:
    """What the tool touches in every one of 8 fixed pseudo-random postures ("" if nothing): a mounting that
    puts it inside the wrist, which no start pose search can mend (found in milliseconds, not seconds)."""
    rng = np.random.default_rng(4)
    lo, hi = sample_range(arm)
    always: set[str] | None = None
    for _ in range(8):
        touching = {pair for pair in contacts(lo + (hi - lo) * rng.random(arm.nv))
                    if ToolSpec.name in pair.split(" / ")}
        always = touching if always is None else always & touching
        if not always:
            return ""
    return ", ".join(sorted(always or ()))


def _hopeless(reason: str) -> bool:
    """Whether a mounting's StartPoseError says that no smaller demos could have a start pose either."""
    return "touches the arm" in reason or NO_TOOL_DOWN in reason


def _words(rpy: Sequence[float]) -> str:
    return f"roll {math.degrees(rpy[0]):g} pitch {math.degrees(rpy[1]):g} deg"


class Mounter:
    """Builds the arm with its tool at a mounting angle (each angle once) and searches the start pose.

    Args:
        stock: The URDF as given.
        spec: The make robot request (tip, tool mass, TOOL_RPY).
        removed: Links after the tip that the description drops.
        chain: The arm's joints, BASE to TIP.
        held: The other movable joints and their positions.
    """

    def __init__(self, stock: str, spec: RobotSpec, removed: tuple[str, ...], chain: Sequence[str],
                 held: Sequence[tuple[str, float]]) -> None:
        self.stock, self.spec, self.removed = stock, spec, removed
        self.chain, self.held = tuple(chain), tuple(held)
        self._built: dict[RPY, tuple[str, ArmModel, Contacts]] = {}
        self._hopeless: dict[RPY, str] = {}  # mountings no demo size can use, and why

    def tool(self, rpy: Sequence[float]) -> ToolSpec:
        return ToolSpec(parent=self.spec.tip, mass=self.spec.tool_mass, com=TOOL_COM, size=TOOL_SIZE,
                        ft_rpy=(float(rpy[0]), float(rpy[1]), float(rpy[2])))

    def build(self, rpy: Sequence[float]) -> tuple[str, ArmModel, Contacts]:
        """(description, jog_arm model, collision check) with the sensor mounted at `rpy`.

        Raises:
            GeneratorError: jog_arm cannot model the arm.
        """
        key = (float(rpy[0]), float(rpy[1]), float(rpy[2]))
        if key not in self._built:
            urdf_xml = build_description(self.stock, self.tool(key), self.removed)
            try:
                arm = ArmModel(urdf_xml, ToolSpec.tip_name, self.chain, held_positions=dict(self.held))
            except KinematicsError as exc:
                raise GeneratorError(f"jog_arm cannot model the {self.spec.name}: {exc}") from exc
            contacts = CollisionChecker(urdf_xml, arm.joint_names, mid_range(arm), dict(self.held)).contacts
            self._built[key] = (urdf_xml, arm, contacts)
        return self._built[key]

    def start_pose(self, rpy: Sequence[float], reach: float, motions: dict, gap: float) -> PoseReport:
        """find_start_pose at this mounting, after the quick check that the tool is not stuck in the arm.

        Raises:
            StartPoseError: Why there is none.
        """
        key = (float(rpy[0]), float(rpy[1]), float(rpy[2]))
        if key in self._hopeless:  # as found for larger demos: smaller ones need not search again
            raise StartPoseError(self._hopeless[key])
        _, arm, contacts = self.build(rpy)
        try:
            stuck = _tool_stuck(arm, contacts)
            if stuck:
                raise StartPoseError(f"the tool, mounted this way, touches the arm in every posture "
                                     f"({stuck})")
            return find_start_pose(arm, reach, lambda tip: motions, heights=_heights(arm, reach, gap),
                                   contacts=contacts)
        except StartPoseError as exc:
            if _hopeless(str(exc)):
                self._hopeless[key] = str(exc)
            raise

    def search(self, reach: float, motions: dict, gap: float, log: Callable[[str], object]) -> Mounting:
        """The user's mounting; else straight, or the adapter angle with the widest margins when straight has
        no start pose or a poor one (worst condition number over POOR_CONDITION, kept only if better).

        Raises:
            NoMountingError: None has a start pose (why, in one line).
        """
        spec = self.spec
        rpy: RPY = spec.tool_rpy if spec.tool_rpy is not None else (0.0, 0.0, 0.0)
        try:
            found = self.start_pose(rpy, reach, motions, gap)
        except StartPoseError as exc:
            if spec.tool_rpy is not None:  # the user's mounting: say why it does not work
                raise NoMountingError(f"TOOL_RPY={','.join(f'{v:g}' for v in rpy)}: {exc}",
                                      _hopeless(str(exc))) from exc
            log("[robot] the straight mounting cannot point the tool down for the demos; trying adapter "
                "angles")
            best = self._adapter(reach, motions, gap, f"straight on {spec.tip}: {exc}", log)
            log(self.chosen(best.rpy))
            return Mounting(*self._fields(best), adapter=(
                "an adapter make robot chose: the straight mounting had no tool-down start pose, this angle "
                f"keeps the most margin ({best.found.min_margin:.2f} rad)"))
        straight = Mounting(rpy, *self.build(rpy), found)
        if spec.tool_rpy is not None or found.worst_condition <= POOR_CONDITION:
            return straight
        log(f"[robot] the straight mounting's demos reach condition number {found.worst_condition:.2f} (over "
            f"{POOR_CONDITION:g}); trying adapter angles")
        try:
            better = self._adapter(reach, motions, gap, "", log)
        except NoMountingError:
            better = None
        if better is None or better.found.worst_condition >= found.worst_condition:
            log("[robot] straight kept: no adapter angle does better")
            return straight
        log(self.chosen(better.rpy))
        return Mounting(*self._fields(better), adapter=(
            f"an adapter make robot chose: the straight mounting's demos reached condition number "
            f"{found.worst_condition:.2f}, this angle's {better.found.worst_condition:.2f}"))

    @staticmethod
    def _fields(m: Mounting) -> tuple[RPY, str, ArmModel, Contacts, PoseReport]:
        return m.rpy, m.urdf_xml, m.arm, m.contacts, m.found

    @staticmethod
    def chosen(rpy: Sequence[float]) -> str:
        given = ",".join(f"{v:.10g}" for v in rpy)
        return f"[robot] adapter chosen: TOOL_RPY={given} ({_words(rpy)}), into config/description.args"

    def _adapter(self, reach: float, motions: dict, gap: float, straight: str,
                 log: Callable[[str], object]) -> Mounting:
        """The adapter angle (of ADAPTERS) whose start pose keeps the widest joint-limit margin on the demos'
        motions (ties: the lower worst condition number).

        Raises:
            NoMountingError: No angle works either (the straight mounting's reason, and the angles tried).
        """
        best: tuple[tuple[float, float], Mounting] | None = None
        hopeless = _hopeless(straight)
        for rpy in ADAPTERS:
            try:
                found = self.start_pose(rpy, reach, motions, gap)
            except StartPoseError as exc:
                touching = str(exc) if "touches the arm" in str(exc) else ""
                hopeless = hopeless and _hopeless(str(exc))
                log(f"[robot]   adapter {_words(rpy)}: no start pose{f' ({touching})' if touching else ''}")
                continue
            log(f"[robot]   adapter {_words(rpy)}: margin {found.min_margin:.2f} rad, condition <= "
                f"{found.worst_condition:.2f}")
            key = (-round(found.min_margin, 3), found.worst_condition)
            if best is None or key < best[0]:
                best = (key, Mounting(rpy, *self.build(rpy), found))
        if best is None:
            raise NoMountingError(
                f"{straight}; nor with the sensor on an adapter at 45 or 90 degrees about the flange's x or"
                " y axis: give the mounting with TOOL_RPY=roll,pitch,yaw", hopeless)
        return best[1]
