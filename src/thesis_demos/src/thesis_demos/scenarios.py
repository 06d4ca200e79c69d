"""The four thesis demonstrations, a fifth (surface following), a sixth (teach and replay), a seventh (peg in
hole, a contact_tasks task) and an eighth (a path at a force over a curved part) as data: laws, pushes, what
to judge.

Pure: no rospy. Forces are in the robot's base frame [N]; velocities [m/s]; distances [m].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from thesis_demos.geometry import SURFACE_DIRECTION, SURFACE_TRAVEL, DemoGeometry, RobotSetup, fit_l

__all__ = ["SCENARIOS", "AxisLaw", "FollowUp", "PathDemo", "Push", "Scenario", "TaskDemo", "TeachL",
           "build_scenarios", "by_name", "curved_surface", "fitted", "peg_in_hole"]

AXES = ("x", "y", "z", "rx", "ry", "rz")
# cartesian_impedance_msgs/ControlLaw
NONE, FOLLOWER, SPRING, COMPLIANT_MOVE = 0, 1, 2, 3
# compliant_control_msgs/AxisLaw: offered through configure_laws only
FORCE_TRACKING = 4


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
    target_force: float = 0.0  # [N] force tracking's target, as the sensor reads the contact (table below: +)


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
class FollowUp:
    """Laws sent (for every axis, replacing the first ones bumplessly) once a force has settled.

    Sent when the controller's force on `axis` stayed within `tolerance` [N] of `target` [N] for `hold` [s].
    """

    laws: dict[str, AxisLaw]
    axis: str
    target: float
    tolerance: float
    hold: float = 0.5


@dataclass(frozen=True)
class TeachL:
    """The L the simulated hand guides the tool along (teach and replay).

    `corner`: where it starts, (x, y) offset from the start pose's tool tip [m]; `legs`: signed lengths along
    X, then along Y [m].
    """

    corner: tuple[float, float]
    legs: tuple[float, float]


@dataclass(frozen=True)
class TaskDemo:
    """A task of contact_tasks' tasks folder, the scene it needs and what it must achieve.

    `scene`: the robot package's sim.launch arguments for it (also the emulated driver's), as pairs.
    """

    task: str
    scene: tuple[tuple[str, str], ...]
    depth: float = 0.015  # [m] inserted at least this far past the plate's top
    within: float = 45.0  # [s] the task's whole time at most
    max_force: float = 25.0  # [N] peak |F|
    max_torque: float = 2.0  # [Nm] peak |T|


@dataclass(frozen=True)
class PathDemo:
    """A path at a force over a curved part (contact_tasks' ~follow_path), the scene it needs and its bounds.

    The path is planned on the nominal cylinder (axis along y, `radius`, its top at the obstacle's top
    centre), `middle` [rad] from the top toward +x; the scene's cylinder is off that by a seeded offset.
    """

    scene: tuple[tuple[str, str], ...]
    radius: float = 0.25  # [m] mujoco_driver's cylinder
    length: float = 0.3  # [m]
    speed: float = 0.02  # [m/s]
    force: float = 10.0  # [N]
    middle: float = 0.0  # [rad]
    force_rms: float = 1.5  # [N] RMS of the force along the tool's axis minus the target, at most
    force_max: float = 20.0  # [N] |F| at most
    contact: float = 0.98  # of the path in contact (> 3 N) at least
    angle_rms: float = 3.0  # [deg] the tool's axis to the normal, RMS at most
    angle_max: float = 8.0  # [deg]
    lateral: float = 0.002  # [m] sideways from the path at most


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
    follow_up: FollowUp | None = None  # a second request during the run (surface following: the X move)
    teach: TeachL | None = None  # the L taught by hand (its own flow: thesis_demos.teach_client)
    press_force: float = 0.0  # [N] force tracking's target on a pressed replay (0: none)
    task: TaskDemo | None = None  # a contact_tasks task in a scene of its own (its own flow: task_client)
    path: PathDemo | None = None  # a path at a force in a scene of its own (its own flow: path_client)

    @property
    def scene(self) -> tuple[tuple[str, str], ...]:
        """The sim.launch arguments this demonstration needs beyond the robot package's scene."""
        if self.task is not None:
            return self.task.scene
        return self.path.scene if self.path is not None else ()

    @property
    def uses_laws_service(self) -> bool:
        """Force tracking exists only in compliant_control_msgs/ConfigureLaws (configure_laws)."""
        laws = list(self.laws.values()) + (list(self.follow_up.laws.values()) if self.follow_up else [])
        return any(law.law == FORCE_TRACKING for law in laws)

    @property
    def tracks_force(self) -> bool:
        """Some part holds a contact force (force tracking): the sensor's noise must allow its tolerance."""
        return self.uses_laws_service or self.press_force > 0.0


# The hybrid's push up on Z [s]: from 1.5 s, for 2 s (the compliant move on X must still run when it ends and
# the spring has brought Z back: robot_setup slows a short move so that it does).
HYBRID_PUSH_START, HYBRID_PUSH_DURATION = 1.5, 2.0


# Thesis section 6.4, with the numbers it gives. Where it is silent: pushes of 5 N (follower) and
# 15 N (spring), V_desired -0.01 m/s (down, onto the obstacle: a usual approach speed for contact,
# and the contact force grows with it) and -0.05 m/s along X. Directions and distances depend on the arm and
# come from its package (config/demos.yaml, see thesis_demos.geometry); the defaults are the thesis-sized
# ones (0.30 m toward the base). The compliant move backs off from the obstacle once it stops
# (exceeded_action move_away): a position-controlled arm that stopped on contact otherwise keeps pressing on
# it with what it overshot (up to 9 N on a simulated arm).
def build_scenarios(geometry: DemoGeometry | None = None) -> tuple[Scenario, ...]:
    """The four demonstrations with an arm's directions and distances (the thesis-sized ones when None)."""
    g = geometry or DemoGeometry()
    f, t = g.follower_push_force, g.follower_push_duration
    return (
        Scenario(
            name="follower_z",
            title="Follower law on Z (b = 30)",
            laws={"z": AxisLaw(FOLLOWER, damping=30.0)},
            pushes=(Push(1.0, t, (0.0, 0.0, f)), Push(2.7 + t, 0.5, (4.0, 4.0, 0.0))),
            duration=4.7 + t,
            controlled=("z",),
        ),
        Scenario(
            name="compliant_move_z",
            title=(
                f"Compliant move on Z toward an obstacle (max force {g.contact_force_limit:g} N, max torque "
                "0.5 Nm), then move away"
            ),
            laws={
                "z": AxisLaw(
                    COMPLIANT_MOVE,
                    damping=30.0,
                    velocity=g.compliant_direction * g.compliant_speed,
                    force_limit=g.contact_force_limit,
                    torque_limit=0.5,
                    max_travel=g.compliant_max_travel,
                )
            },
            duration=max(11.0, 1.5 * g.compliant_max_travel / g.compliant_speed),
            end_when_move_ends=True,
            controlled=("z",),
            exceeded_action="move_away",
        ),
        Scenario(
            name="spring_x",
            title="Spring law on X (b = 30, k = 100)",
            laws={"x": AxisLaw(SPRING, damping=30.0, stiffness=100.0)},
            pushes=(Push(1.0, 3.0, (g.spring_direction * g.spring_push_force, 0.0, 0.0)),),
            duration=7.0,
            controlled=("x",),
        ),
        Scenario(
            name="hybrid",
            title=(
                f"Hybrid: compliant move on X (max path deviation {g.hybrid_travel:.2f} m) with spring on Z "
                "(b = 30, k = 100)"
            ),
            laws={
                "x": AxisLaw(
                    COMPLIANT_MOVE,
                    damping=30.0,
                    velocity=g.hybrid_direction * g.hybrid_speed,
                    force_limit=g.contact_force_limit,
                    torque_limit=0.5,
                    max_travel=g.hybrid_travel,
                ),
                "z": AxisLaw(SPRING, damping=30.0, stiffness=100.0),
            },
            pushes=(Push(HYBRID_PUSH_START, HYBRID_PUSH_DURATION, (0.0, 0.0, 15.0)),),
            duration=max(9.0, 3.0 + 1.5 * g.hybrid_travel / g.hybrid_speed),
            end_when_move_ends=True,
            controlled=("x", "z"),
        ),
        surface_following(),
        teach_and_replay(),
        peg_in_hole(),
        curved_surface(g.curved_middle, g.curved_length),
    )


# Surface following (the fifth demonstration, not in the thesis): Z presses on the obstacle block's top with a
# set force while X moves over it. Named here so they can later come from the robot package's configuration.
# The block is 15 cm wide with the tool tip over its centre at the start pose (both robots' sim.yaml), and the
# tool is a 3 cm radius cylinder: 4 cm of travel along -X keeps the whole tool face on the block.
SURFACE_TARGET_FORCE = 10.0  # [N] pressing down: the block pushes the tool up (+Z) with this
SURFACE_TOLERANCE = 1.5  # [N] the mean over the travel must be this close to the target
SURFACE_DAMPING = 2000.0  # [N/(m/s)] b against ~20 N/mm of a stiff arm on a block (contact_control README)
# [m/s] down onto the block until the force reaches half the target: touching at 0.01 m/s overshot to 21 N on
# a simulated arm (the filtered force and the arm lag ~70 ms behind the contact) and tripped the 25 N limit.
SURFACE_APPROACH_SPEED = 0.005
SURFACE_FORCE_LIMIT = 20.0  # [N] ends the press (move_away) well under the 25 N global limit
SURFACE_VELOCITY = SURFACE_DIRECTION * 0.01  # [m/s] along X (toward the base: clear on both robots)
SURFACE_SETTLE = 0.5  # [s] after X starts, left out of the figures (X speeding up, friction building up)

_PRESS = AxisLaw(
    FORCE_TRACKING,
    damping=SURFACE_DAMPING,
    velocity=SURFACE_APPROACH_SPEED,
    force_limit=SURFACE_FORCE_LIMIT,
    target_force=SURFACE_TARGET_FORCE,
)



def surface_following() -> Scenario:
    """The fifth demonstration (not in the thesis), the same on every arm: it presses on the obstacle."""
    return Scenario(
        name="surface_following",
        title=f"Surface following: Z tracks {SURFACE_TARGET_FORCE:g} N on the block's top while X moves "
        f"{SURFACE_TRAVEL * 100:g} cm",
        laws={"z": _PRESS},
        duration=25.0,
        end_when_move_ends=True,
        settle=0.5,
        controlled=("x", "z"),
        exceeded_action="move_away",
        follow_up=FollowUp(
            laws={
                "z": _PRESS,
                "x": AxisLaw(COMPLIANT_MOVE, velocity=SURFACE_VELOCITY, max_travel=SURFACE_TRAVEL),
            },
            axis="z",
            target=SURFACE_TARGET_FORCE,
            tolerance=0.5,
        ),
    )


# Teach and replay (the sixth demonstration): the simulated human guides the tool along an L (10 cm
# along X, then 5 cm along Y, scaled to the block by geometry.fit_l) with hand-guiding on while teach's
# program_server records it; the program is replayed in free space at its speed and at twice it, then pressing
# on the block with Z force tracking at SURFACE_TARGET_FORCE.
TEACH_LEGS = (0.10, 0.05)  # [m] the L, along X then Y
TEACH_PUSH = 6.0  # [N] the hand's push while guiding: 6 / 50 N/(m/s) (guide_damping_linear) = 0.12 m/s
TEACH_PATH_RMS = 0.002  # [m] a free-space replay stays this close to the recorded path (RMS) ...
TEACH_PATH_MAX = 0.005  # [m] ... and at most this far
TEACH_FAST = 2.0  # the second free-space replay's speed factor
# The pressed replay's top speed [m/s] (its speed factor: this over the taught L's top speed): surface
# following's. Sliding on the simulated block (friction about 1 x the normal force) at a quarter of the hand's
# 0.12 m/s (3 cm/s) stick-slipped between 2 and 15 N (50 ms means 8.9 to 12.2 N).
TEACH_PRESS_VELOCITY = abs(SURFACE_VELOCITY)


def teach_and_replay(
    corner: tuple[float, float] = (0.0, 0.0),
    legs: tuple[float, float] = (SURFACE_DIRECTION * TEACH_LEGS[0], TEACH_LEGS[1]),
) -> Scenario:
    """The sixth demonstration; `corner` and `legs` as geometry.fit_l gives them for an arm's block."""
    return Scenario(
        name="teach_and_replay",
        title=f"Teach by hand an L of {abs(legs[0]) * 100:.0f} x {abs(legs[1]) * 100:.0f} cm, replay it at "
        f"1 x and {TEACH_FAST:g} x, then pressing {SURFACE_TARGET_FORCE:g} N on the block",
        laws={},
        # What the hand pushes with (the flow pushes each leg until the tool is nearly there).
        pushes=(Push(0.0, 0.0, (TEACH_PUSH * math.copysign(1.0, legs[0]), 0.0, 0.0)),
                Push(0.0, 0.0, (0.0, TEACH_PUSH * math.copysign(1.0, legs[1]), 0.0))),
        duration=240.0,  # [s] the whole flow at most
        controlled=("x", "y", "z"),
        exceeded_action="move_away",
        teach=TeachL(corner, legs),
        press_force=SURFACE_TARGET_FORCE,
    )


# Peg in hole (the seventh demonstration): contact_tasks' shipped task, unchanged, on the hole fixture with
# the peg tool. The hole is drawn from a seed within 4 mm and 2 degrees of the block's top centre
# (mujoco_driver's hole_seed): the task is told only where the plate's top would be.
PEG_HOLE_SEED = 1
PEG_HOLE_CLEARANCE = 0.0004  # [m] a 10.4 mm hole for the 10 mm peg


def peg_in_hole() -> Scenario:
    """The seventh demonstration (not in the thesis): search, seat and insert under position uncertainty."""
    scene = (("fixture", "hole"), ("tool", "peg"), ("hole_seed", str(PEG_HOLE_SEED)),
             ("hole_clearance", str(PEG_HOLE_CLEARANCE)))
    return Scenario(
        name="peg_in_hole",
        title=f"Peg in hole: a 10 mm square peg into a {10 + PEG_HOLE_CLEARANCE * 1e3:g} mm hole off its "
        "nominal pose (contact_tasks' peg_in_hole task)",
        laws={},
        duration=45.0,
        controlled=("x", "y", "z"),
        task=TaskDemo("peg_in_hole", scene),
    )


# A curved part (the eighth demonstration): mujoco_driver's cylinder drawn from a seed within 10 mm of its
# nominal place (surface_seed), the ball-end tool (a flat face bears on its edge on a convex part:
# contact_tasks' README, Paths at a force).
CURVED_SEED = 3


def curved_surface(middle: float = 0.0, length: float = 0.3) -> Scenario:
    """The eighth demonstration (not in the thesis): a 0.3 m path over a cylinder at 20 mm/s pressing 10 N,
    planned on the nominal cylinder, run on the offset one (`middle`, `length`: the arm's, demos.yaml)."""
    scene = (("fixture", "cylinder"), ("tool", "ball"), ("surface_seed", str(CURVED_SEED)))
    demo = PathDemo(scene, length=length, middle=middle)
    return Scenario(
        name="curved_surface",
        title=f"Curved surface: a {demo.length:g} m path over a {demo.radius:g} m cylinder off its nominal "
        f"place at {demo.speed * 1e3:g} mm/s pressing {demo.force:g} N, the tool kept normal",
        laws={},
        duration=demo.length / demo.speed + 40.0,
        controlled=("x", "z", "ry"),
        path=demo,
    )


SCENARIOS: tuple[Scenario, ...] = build_scenarios()


def by_name(names: list[str] | None, geometry: DemoGeometry | None = None) -> list[Scenario]:
    """The scenarios named (all when None or empty), with an arm's geometry (thesis-sized when None).

    Raises:
        KeyError: an unknown name.
    """
    scenarios = SCENARIOS if geometry is None else build_scenarios(geometry)
    if not names:
        return list(scenarios)
    known = {s.name: s for s in scenarios}
    missing = [n for n in names if n not in known]
    if missing:
        raise KeyError(f"unknown demo(s) {missing}; known: {sorted(known)}")
    return [known[n] for n in names]


def fitted(setup: RobotSetup, scenarios: Sequence[Scenario], tip: Sequence[float]) -> list[Scenario]:
    """`scenarios` with the teach-and-replay L fitted to the arm's block (geometry.fit_l; unchanged without
    a scene or when it does not fit: the preflight says why)."""
    if not setup.checks_scene:
        return list(scenarios)
    corner_and_legs = fit_l(tip, setup.obstacle, setup.tool_radius)
    if isinstance(corner_and_legs, str):
        return list(scenarios)
    return [teach_and_replay(*corner_and_legs) if s.teach is not None else s for s in scenarios]
