"""One control cycle of the jog_arm server: Cartesian twist in, joint positions and velocities out.

:class:`JogCalcs` coordinates parts that each live in a module of their own, and keeps only what links one
cycle to the next (the last output, whether the arm is moving, the twist filter). Pipeline of
:meth:`JogCalcs.step` (all arrays preallocated, model and data built once):

1. Reference configuration: the last commanded one while moving (``integrate_from: commanded``; re-synced
   to the measured state (:mod:`~jog_arm.measured_joints`) when they differ by more than
   ``max_tracking_error``), else the measured one.
2. Jacobian of the tip at the reference, weighted, its condition number and the damped factorisation
   (:mod:`~jog_arm.damped_solver`).
3. The command's twist (SI units after ``unitless`` scaling, :mod:`~jog_arm.command_state`) rotated from its
   frame (:mod:`~jog_arm.command_frames`) into the root frame.
4. Singularity scale, only if the condition number grows along the commanded joint motion (predicted by
   a finite difference), so a command that backs out is never slowed; then the collaborative speed cap
   (:mod:`~jog_arm.speed_cap`); both scale the twist.
5. Low-pass filter of the twist in root axes (unit DC gain, reset to the twist of the current output when
   motion (re)starts); joint velocity from the damped pseudo-inverse, on redundant arms plus a null-space
   pull toward the posture. (Filtering joint velocities blends J⁺ of past configurations: the tip drifts
   sideways while the Jacobian changes.)
5b. Straightening: a joint step of more than 1 mrad per period (slow output rates: a trajectory every
   50 ms) moves the tip on a curve; one Newton step puts the step's end where the twist would take the tip.
   Together with 5, a 20 Hz 7-joint follower's sideways drift over 15 cm fell from 5.2 mm to 0.00 mm.
6. Joint position limits (ramp down before the margin, stop at it, braking within the acceleration
   limit; moving away always allowed), then velocity limits, then acceleration limits: each scales the
   WHOLE vector, never one joint (:meth:`~jog_arm.limits.JointLimiter.limit`).
7. Positions = reference + velocity x ``pub_period`` (the fork divided by the computation time instead).

A stale, zero, invalid or paused command makes the target zero: the output decelerates within the
acceleration limits to exactly zero, then the zero command is repeated
``num_outgoing_halt_msgs_to_publish`` times and publishing stops until a new command arrives.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import pinocchio as pin
from compliant_common.typedefs import FloatArray

from jog_arm.command_frames import CommandFrames
from jog_arm.command_state import CommandResult, CommandState
from jog_arm.damped_solver import DampedSolver
from jog_arm.filters import LowPassFilter
from jog_arm.kinematics import ArmModel, KinematicsError
from jog_arm.limits import JointLimiter
from jog_arm.measured_joints import MeasuredJoints
from jog_arm.settings import JogSettings, SettingsError
from jog_arm.speed_cap import SpeedCap
from jog_arm.status import StatusCode, motion_status

__all__ = ["CommandResult", "JogCalcs", "JogOutput", "Point"]

Point = tuple[tuple[float, ...], tuple[float, ...], float]  # positions, velocities, time_from_start [s]


class JogOutput(NamedTuple):
    """Result of one cycle: a new one per :meth:`JogCalcs.step` (immutable; its tuples are its own).

    Attributes:
        publish: Whether the node should publish this cycle (False before the first command and after
            the final zero command has been repeated).
        positions: Joint positions of the next point [rad], in `JogCalcs.joint_names` order.
        velocities: Joint velocities [rad/s], same order.
        status: Why the output is what it is.
        message: Human-readable detail of `status`.
        condition_number: Of the tip Jacobian at the reference configuration (last computed; NaN before
            the first).
        speed_scale: Product of the singularity, speed cap, joint-limit and velocity scales applied to the
            command (0 when there is nothing to follow).
        speed_cap: The collaborative speed cap in the commanded direction [m/s] (inf: off, or no
            translation commanded).
    """

    publish: bool
    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    status: StatusCode
    message: str
    condition_number: float
    speed_scale: float
    speed_cap: float


def _jog_output(publish: bool, positions: tuple[float, ...], velocities: tuple[float, ...],
                status: StatusCode, message: str, condition_number: float, speed_scale: float,
                speed_cap: float = math.inf) -> JogOutput:
    """`JogOutput(...)` in one allocation instead of two (and faster): calling the class with more than four
    fields allocates the call's argument array as well."""
    return tuple.__new__(JogOutput, (publish, positions, velocities, status, message, condition_number,
                                     speed_scale, speed_cap))


class JogCalcs:
    """Turns Cartesian velocity commands into joint commands for one serial arm.

    Not thread-safe: the ROS node serialises calls with a lock.

    Args:
        settings: Validated parameters.
        urdf_xml: The robot description (URDF string).

    Raises:
        KinematicsError: The URDF lacks a configured frame or joint.
        SettingsError: A parameter does not fit the model (e.g. the posture's length).

    Attributes:
        joints: The measured joint state and the joint orders.
        command_frames: The frames commands may be expressed in.
        command: The twist command being followed, pause and suspension.
        solver: The damped least-squares solver.
        limiter: The joint position, velocity and acceleration limits.
    """

    def __init__(self, settings: JogSettings, urdf_xml: str) -> None:
        self.settings = settings
        self.model = ArmModel(
            urdf_xml,
            settings.ee_frame_name,
            settings.joint_names,
            settings.joint_limits,
            settings.default_max_acceleration,
            settings.held_joints,
        )
        if not self.model.has_frame(settings.planning_frame):
            raise KinematicsError(
                f"planning_frame {settings.planning_frame!r} is not a frame of the robot model"
            )
        model_names = self.model.joint_names
        n = self.nv = self.model.nv
        if n < 3:
            raise KinematicsError(
                f"jog_arm needs at least 3 controlled joints to move the tip in 3-D, got {list(model_names)}"
            )
        #: Joint order of every array given to and returned by this class.
        self.joint_names: tuple[str, ...] = settings.joint_names or model_names
        self.joints = MeasuredJoints(self.model, self.joint_names)
        self._to_user = self.joints.to_user  # model index of each user joint (tests read it here)
        self._period = settings.pub_period
        self.limiter = JointLimiter(
            self.model.lower,
            self.model.upper,
            self.model.max_velocity,
            self.model.max_acceleration,
            [settings.prismatic_limit_margin if linear else settings.joint_limit_margin
             for linear in self.model.prismatic],
            [settings.prismatic_slowdown_width if linear else settings.joint_limit_slowdown_width
             for linear in self.model.prismatic],
            settings.pub_period,
            settings.contact_stop_scale,
        )
        #: Set by the stage while a contact stops the arm: the limiter brakes at contact_stop_scale.
        self.braking = False
        self._filter = LowPassFilter(settings.low_pass_filter_coeff, 6)  # on the twist
        self._x_filtered = np.zeros(6)
        self._from_commanded = settings.integrate_from == "commanded"
        posture: FloatArray | None = None  # model order; None: where motion starts
        if settings.nullspace_posture:
            if len(settings.nullspace_posture) != n:
                raise SettingsError(
                    f"jog_arm_server/nullspace_posture has {len(settings.nullspace_posture)} values "
                    f"for {n} joints"
                )
            posture = self.joints.model_order(settings.nullspace_posture)
        pulled = None  # model order, 1 for a joint the null space pulls; None: every joint
        if settings.nullspace_joints:
            unknown = [j for j in settings.nullspace_joints if j not in self.model.joint_names]
            if unknown:
                raise SettingsError(f"jog_arm_server/nullspace_joints: {unknown} are not controlled joints "
                                    f"{list(self.model.joint_names)}")
            pulled = np.array([float(j in settings.nullspace_joints) for j in self.model.joint_names])
        self.solver = DampedSolver(self.model, settings, posture, pulled)
        #: The collaborative speed cap (ISO/TS 15066).
        self.speed_cap = SpeedCap(self.model, settings.singularity_length_scale,
                                  settings.collaborative_region, settings.collaborative_payload)
        self.command_frames = CommandFrames(self.model)
        self.command = CommandState(settings, self.command_frames)

        # What links one cycle to the next, model order (float lists: faster than numpy for 6-7 values).
        self._q_cmd = [0.0] * n
        self._dq_out = [0.0] * n
        self._running = False  # True from motion start until the final zero command was repeated
        self._filter_live = False
        self._zero_sent = settings.num_outgoing_halt_msgs_to_publish  # silent until the first command
        self._zeros = (0.0,) * n
        self._condition = math.nan  # of the last Jacobian computed by a step
        self._uncontrolled: tuple[list[float] | None, list[tuple[float, float, float]]] = (None, [])
        self._planning_id = pid = self.model.frame_id(settings.planning_frame)
        frame = self.model.model.frames[pid]  # its rotation in the root, if fixed to the root
        self._planning_rotation = frame.placement.rotation.copy() if frame.parentJoint == 0 else None

    def retune(self, settings: JogSettings) -> None:
        """Live tuning (settings.TUNABLE, already validated): unitless scales, command timeout, twist filter
        (continuing from its memories), singularity thresholds and damping. The joint limiter still bounds
        every joint's acceleration, so no change steps the arm's velocity beyond it."""
        self.settings = settings
        self.command.retune(settings)
        self._filter.set_coeff(settings.low_pass_filter_coeff)
        self.solver.retune(settings)
        self.speed_cap.configure(settings.collaborative_region, settings.collaborative_payload)

    # --- inputs ---------------------------------------------------------------------------------------

    def set_joint_state(self, positions: Sequence[float], now: float | None = None) -> None:
        """Sets the measured joint positions [rad], in `joint_names` order, received at `now` [s] (None: its
        age is not checked).

        Raises:
            ValueError: Wrong length or a non-finite value (the previous state is kept).
        """
        self.joints.set(positions, now)

    def set_joint_state_named(
        self, names: Sequence[str], positions: Sequence[float], now: float | None = None
    ) -> bool:
        """Sets the measured positions from a JointState-like (names, positions) pair received at `now` [s].

        Extra joints are ignored. Returns False, keeping the previous state, if a controlled joint is
        missing or a value is not finite.
        """
        return self.joints.set_named(names, positions, now)

    def has_frame(self, name: str) -> bool:
        """True if commands in frame `name` can be resolved (model frame or added with :meth:`add_frame`)."""
        return self.command_frames.resolve(name) is not None

    def add_frame(self, name: str, parent: str, rotation: FloatArray) -> None:
        """Makes a frame the model does not know usable for commands, fixed relative to a model frame
        (see `CommandFrames.add`).

        Raises:
            KinematicsError: `parent` is unknown.
            ValueError: `rotation` is not a rotation matrix.
        """
        self.command_frames.add(name, parent, rotation)

    def set_command(self, twist: Sequence[float], frame: str, now: float) -> CommandResult:
        """Sets the commanded twist of the tip.

        Args:
            twist: (vx, vy, vz, wx, wy, wz): velocity of the tip's origin and angular velocity, with the
                axes of `frame`; unitless in [-1, 1] or m/s and rad/s per `command_in_type`.
            frame: Frame of the twist's axes; "" = `cmd_frame` (or `planning_frame`).
            now: Receive time [s] (staleness is measured from it).

        Returns:
            Whether it was accepted and why not. A refused command (non-finite, out of range or in an unknown
            frame) makes the arm stop (smoothly if moving) until a valid one arrives.
        """
        return self.command.set(twist, frame, now)

    def drop_command(self, reason: str) -> None:
        """Forgets the current command (its source vanished): the arm decelerates to rest at once instead of
        after `incoming_cmd_timeout`; the next command moves it again."""
        self.command.drop(reason)

    def clock_jumped(self, description: str) -> None:
        """The clock jumped: the command's and the joint state's ages are unknown, so the command is dropped
        and the arm halts until a joint state received after the jump (then the next command moves it)."""
        self.command.drop(f"{description}: command dropped")
        self.joints.clock_jumped()

    def suspend(self, reason: str) -> None:
        """Decelerates to rest and refuses commands until :meth:`unsuspend` (e.g. the master is lost)."""
        self.command.suspend(reason)

    def halt(self, reason: str) -> None:
        """The robot stopped by itself (its driver holds it): refuses commands like :meth:`suspend`, but with
        nothing to decelerate: the output is zero at once and the next motion starts from the measured
        joints, so resuming does not jump to where a deceleration would have taken the arm."""
        self.command.suspend(reason)
        self._dq_out = [0.0] * self.nv
        self._running = self._filter_live = False
        self._zero_sent = 0

    def unsuspend(self) -> None:
        """Accepts commands again; the arm stays at rest until the next one."""
        self.command.unsuspend()

    def pause(self) -> None:
        """Stops (smoothly) and ignores commands until :meth:`resume`."""
        self.command.pause()

    def resume(self) -> None:
        """Accepts commands again; motion restarts with the next command (the old one is dropped)."""
        self.command.resume()

    @property
    def measured(self) -> list[float] | None:
        """The last measured joint positions in model order (a new list per joint state; do not modify),
        None before the first."""
        joints = self.joints
        return joints.positions if joints.received else None

    @property
    def paused(self) -> bool:
        """Whether :meth:`pause` is in effect."""
        return self.command.paused

    @property
    def silent(self) -> bool:
        """At rest with the halt command repeated: nothing is published until the next command."""
        return not self._running

    # --- the cycle ------------------------------------------------------------------------------------

    def step(self, now: float) -> JogOutput:
        """Runs one control cycle: what to follow, then the stages follow -> limit -> integrate.

        Args:
            now: Current time [s], same clock as the `now` given to :meth:`set_command`.

        Returns:
            This cycle's :class:`JogOutput`.
        """
        joints = self.joints
        if not joints.received:
            zeros = self._zeros
            return _jog_output(False, zeros, zeros, StatusCode.NO_JOINT_STATE, "no joint state received yet",
                               self._condition, 0.0)
        # 1. Reference configuration (plain float lists: cheaper than numpy for 6-7 values).
        q_ref, resynced = self._reference()
        status, message = self.command.status(now, joints.time)
        follow = status == StatusCode.NO_WARNING and not self.command.zero
        if not follow and not any(self._dq_out):
            return self._hold(q_ref, status, message)
        # 2.-5. Joint velocity for the twist (zero when there is nothing to follow).
        s_cap = 1.0
        if follow:
            dq, condition, s_sing, s_cap = self._follow(q_ref)
            dq = self.solver.straighten(q_ref, dq)
        else:
            dq, condition, s_sing = self._no_follow(q_ref)
        # 6. Position, velocity and acceleration limits.
        dq_new, s_pos, s_vel = self.limiter.limit(q_ref, dq, self._dq_out, not follow, self.braking)
        self._dq_out = dq_new
        # 7. Integrate over the publish period.
        q_cmd = self._q_cmd = self._integrate(q_ref, dq_new)

        self._condition = condition
        cap = self.speed_cap.last if follow else None
        if follow:
            self._zero_sent = 0
            status, message = motion_status(condition, s_sing, s_pos, s_vel, s_cap)
            if status == StatusCode.COLLABORATIVE_SPEED_CAP:
                message = self._cap_message()
            speed_scale = s_sing * s_cap * s_pos * s_vel
        else:
            speed_scale = 0.0
            if not any(dq_new):
                self._zero_sent = 1
            if not message:
                message = "stopping"
        if resynced:
            message += " (re-synced to the measured joint state: tracking error above max_tracking_error)"
        return _jog_output(True, joints.user_order(q_cmd), joints.user_order(dq_new), status, message,
                           condition, speed_scale, math.inf if cap is None else cap.speed)

    def _cap_message(self) -> str:
        cap, region = self.speed_cap.last, self.speed_cap.region
        assert region is not None  # a cap below 1 needs a region
        return (f"speed capped to {cap.speed:.3f} m/s toward the {region.name} (ISO/TS 15066: "
                f"{region.transient_force:g} N; effective mass {cap.robot_mass:.2f} kg)")

    def _start_running(self, q_arr: FloatArray) -> None:
        if not self._running:
            self._running = True
            self.solver.start_motion(q_arr)

    def _no_follow(self, q_ref: list[float]) -> tuple[list[float], float, float]:
        """Decelerating with nothing to follow: target zero (the condition number still reported)."""
        geometry = self.solver.geometry(q_ref)
        self._start_running(geometry.q_arr)
        self._filter_live = False
        return [0.0] * self.nv, geometry.condition, 1.0

    def _follow(self, q_ref: list[float]) -> tuple[list[float], float, float, float]:
        """Stages 2-5: the filtered joint velocity for the twist, the condition number, the singularity scale
        and the speed cap's scale applied."""
        solver = self.solver
        # 2. Jacobian, condition number, factorised damped J·Jᵀ (computed ahead by prefetch() if it could).
        geometry = solver.geometry(q_ref)
        q_arr, J, condition = geometry.q_arr, geometry.J, geometry.condition
        self._start_running(q_arr)
        # 3. Twist in root axes.
        x = self.command.in_root_axes(q_arr)
        # 4. Singularity: judged on the unfiltered joint velocity, so the first cycle that backs out is not
        # slowed.
        s_sing = solver.singularity_slowdown(geometry, x)
        s_cap = self.speed_cap.scale(geometry.q, J, x, s_sing)
        s = s_sing * s_cap
        # 5. Low-pass filter on the scaled twist (root axes), started from the twist of the current output so
        # there is no start-up jump. Filtering joint velocities instead blends J⁺ of past configurations,
        # which moves the tip sideways while the Jacobian changes (2 mm over 15 cm at 20 Hz, 7 joints).
        if not self._filter_live:
            self._filter.reset((J @ np.asarray(self._dq_out)).tolist())
            self._filter_live = True
        xf = self._x_filtered
        xf[:] = self._filter.filter((x * s).tolist() if s != 1.0 else x.tolist())
        return solver.solve(J, xf, q_arr, s_sing).tolist(), condition, s_sing, s_cap

    def _integrate(self, q_ref: list[float], dq: list[float]) -> list[float]:
        """Stage 7: positions = reference + velocity x pub_period (a copy filled in place: 3 allocations
        where a comprehension over zip makes 7)."""
        period = self._period
        q = q_ref.copy()
        for i in range(self.nv):
            q[i] += dq[i] * period
        return q

    def prefetch(self) -> None:
        """Computes the next cycle's twist-independent part now (Jacobian, condition number, factorisation),
        and the speed cap's inverse mass, so the next :meth:`step`, if its reference configuration is still
        this one, only solves for the twist: call it after publishing, off the path from twist to command."""
        if self.joints.received and self._running:
            geometry = self.solver.geometry(self._reference()[0])
            self.speed_cap.prepare(geometry.q, geometry.J)

    def _reference(self) -> tuple[list[float], bool]:
        """(reference configuration of the next step, whether it is a re-sync to the measured state)."""
        joints = self.joints
        if self._running and self._from_commanded:
            q_ref = self._q_cmd
            if joints.strays_from(q_ref, self.settings.max_tracking_error):
                return joints.positions, True
            return q_ref, False
        return joints.positions, False

    def _hold(self, q_ref: list[float], status: StatusCode, message: str) -> JogOutput:
        """Cycle at rest: repeat the zero command a few times, then fall silent."""
        self._filter_live = False
        if self._running:
            self._q_cmd = q_ref
        if self._zero_sent < self.settings.num_outgoing_halt_msgs_to_publish:
            self._zero_sent += 1
            publish = True
        else:
            publish = False
            self._running = False
        return _jog_output(publish, self.joints.user_order(q_ref), self._zeros, status,
                           message or "at rest", self._condition, 0.0)

    # --- outputs and queries --------------------------------------------------------------------------

    def points_ahead(self, out: JogOutput, count: int) -> tuple[Point, ...]:
        """Trajectory points 2..`count` (positions, velocities, time_from_start [s]) after `out`'s own point
        (`out.positions`, `out.velocities`, `pub_period`), for a JointTrajectory: they extrapolate at its
        velocity, kept inside the position limits minus the margin, for controllers that drop points already
        in the past (simu mode)."""
        if count < 2:
            return ()
        q = np.array(out.positions)
        v = np.array(out.velocities)
        lower = np.minimum(self.limiter.lower_stop[self._to_user], q)
        upper = np.maximum(self.limiter.upper_stop[self._to_user], q)
        return tuple(
            (tuple(np.clip(q + v * (self._period * (k - 1)), lower, upper).tolist()), out.velocities,
             self._period * k)
            for k in range(2, count + 1)
        )

    def eef_pose(self, positions: Sequence[float] | None = None) -> pin.SE3:
        """Pose of `ee_frame_name` in `planning_frame` at `positions` (user order) or the last reference."""
        q = self.solver.q_arr.copy() if positions is None else self.joints.model_order(positions)
        self.solver.invalidate()  # frame_pose moves the model's data
        return self.model.frame_pose(q, self.settings.ee_frame_name, self.settings.planning_frame)

    def uncontrolled_rotations(self) -> list[tuple[float, float, float]]:
        """Unit axes of `planning_frame` the tip cannot turn about while its position is kept, at the next
        step's reference configuration (an arm with fewer than six joints; empty with six or more, or before
        the first joint state). Off the control path: the node asks when it publishes the status."""
        task = self.solver.task
        if task is None or not self.joints.received:
            return []
        q_ref = self._reference()[0]
        if self._uncontrolled[0] != q_ref:
            self.solver.geometry(q_ref)  # the task's factorisation at q_ref (reused by the next step)
            planning = self._planning_rotation
            if planning is None:  # a planning frame that moves with the joints
                planning = self.model.frame_rotation(self._planning_id, self.solver.q_arr)
                self.solver.invalidate()  # frame_rotation at q moves the model's data
            axes = task.uncontrolled @ planning  # root axes -> planning_frame axes
            self._uncontrolled = (list(q_ref), [(float(a), float(b), float(c)) for a, b, c in axes])
        return self._uncontrolled[1]
