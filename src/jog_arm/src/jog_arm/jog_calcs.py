"""One control cycle of the jog_arm server: Cartesian twist in, joint positions and velocities out.

Pipeline of :meth:`JogCalcs.step` (all arrays preallocated, model and data built once):

1. Reference configuration: the last commanded one while moving (``integrate_from: commanded``; re-synced
   to the measured state when they differ by more than ``max_tracking_error``), else the measured one.
2. Jacobian of the tip at the reference (Pinocchio, LOCAL_WORLD_ALIGNED), its linear rows divided by
   ``singularity_length_scale`` so metres and radians weigh alike; the singular values come from the
   eigen-decomposition of the 6x6 ``J·Jᵀ`` (eigenpy, a few µs); condition number = largest / smallest
   singular value (valid for 6 and 7 joints, unlike the fork's eigenvalues of J itself).
3. Twist (SI units after ``unitless`` scaling) rotated from its frame into the root frame.
4. Singularity scale, only if the condition number grows along the commanded joint motion (predicted by
   a finite difference), so a command that backs out is never slowed; it scales the twist.
5. Low-pass filter of the twist in root axes (unit DC gain, reset to the twist of the current output when
   motion (re)starts); joint velocity from the damped pseudo-inverse, on redundant arms plus a null-space
   pull toward the posture. (Filtering joint velocities blends J⁺ of past configurations: the tip drifts
   sideways while the Jacobian changes.)
5b. Straightening: a joint step of more than 1 mrad per period (slow output rates: a trajectory every
   50 ms) moves the tip on a curve; one Newton step puts the step's end where the twist would take the tip.
   Together with 5, a 20 Hz 7-joint follower's sideways drift over 15 cm fell from 5.2 mm to 0.00 mm.
6. Joint position limits (ramp down before the margin, stop at it, braking within the acceleration
   limit; moving away always allowed), then velocity limits, then acceleration limits: each scales the
   WHOLE vector, never one joint.
7. Positions = reference + velocity x ``pub_period`` (the fork divided by the computation time instead).

A stale, zero, invalid or paused command makes the target zero: the output decelerates within the
acceleration limits to exactly zero, then the zero command is repeated
``num_outgoing_halt_msgs_to_publish`` times and publishing stops until a new command arrives.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence
from dataclasses import dataclass

import eigenpy
import numpy as np
import pinocchio as pin

from jog_arm.filters import LowPassFilter
from jog_arm.kinematics import ArmModel, KinematicsError
from jog_arm.limits import JointLimiter, singularity_scale
from jog_arm.settings import JogSettings, SettingsError
from jog_arm.status import StatusCode

__all__ = ["CommandResult", "JogCalcs", "JogOutput"]

# Joint-space step [rad, max-norm] of the finite difference that predicts the condition number.
_PREDICTION_STEP = 1e-3
_EIGENVALUES_ONLY = eigenpy.DecompositionOptions.EigenvaluesOnly
# Smallest damping λ² added once damping starts, so J·Jᵀ + λ²I stays invertible at an exact singularity.
_DAMPING_FLOOR = 1e-12
# [rad] a joint step above this per period bends the tip's path enough to straighten (module docstring, 7.)
_STRAIGHTEN_STEP = 1e-3
_STRAIGHTEN_LIMIT = 0.1  # a correction above this fraction of the velocity is not applied


@dataclass(frozen=True)
class CommandResult:
    """Outcome of :meth:`JogCalcs.set_command`.

    Attributes:
        accepted: True if the command is now the target.
        reason: Why it was refused ("" if accepted).
    """

    accepted: bool
    reason: str = ""


class JogOutput:
    """Result of one cycle. One instance per :class:`JogCalcs`, refilled every cycle (its tuples stay valid).

    Attributes:
        positions: Joint positions of the next point [rad], in `JogCalcs.joint_names` order (a tuple).
        velocities: Joint velocities [rad/s], same order (a tuple).
        publish: Whether the node should publish this cycle (False before the first command and after
            the final zero command has been repeated).
        status: Why the output is what it is.
        message: Human-readable detail of `status`.
        condition_number: Of the tip Jacobian at the reference configuration (last computed).
        speed_scale: Product of the singularity, joint-limit and velocity scales applied to the command
            (0 when there is nothing to follow).
    """

    __slots__ = ("condition_number", "message", "positions", "publish", "speed_scale", "status", "velocities")

    def __init__(self, size: int) -> None:
        self.positions: tuple[float, ...] = (0.0,) * size
        self.velocities: tuple[float, ...] = (0.0,) * size
        self.publish = False
        self.status = StatusCode.NO_JOINT_STATE
        self.message = "no joint state received yet"
        self.condition_number = math.nan
        self.speed_scale = 0.0


_ACCEPTED = CommandResult(True)


class _Frame:
    """A command frame resolved against the model: a model frame, possibly with a fixed extra rotation."""

    __slots__ = ("extra", "frame_id", "on_chain", "static", "static_rows")

    def __init__(
        self, frame_id: int, static: np.ndarray | None, on_chain: bool, extra: np.ndarray | None
    ) -> None:
        self.frame_id = frame_id
        self.static = static  # root <- frame rotation if it never moves, else None
        self.static_rows = None if static is None else tuple(map(tuple, static.tolist()))
        self.on_chain = on_chain
        self.extra = extra  # model frame <- command frame rotation, or None


class _Geometry:
    """What a cycle needs that does not depend on the twist, at configuration `q` (see JogCalcs._geometry)."""

    __slots__ = ("J", "condition", "q", "q_arr", "valid")

    def __init__(self) -> None:
        self.valid = False
        self.q: list[float] = []
        self.q_arr: np.ndarray = np.zeros(0)
        self.J: np.ndarray = np.zeros((6, 0))
        self.condition = math.inf


class JogCalcs:
    """Turns Cartesian velocity commands into joint commands for one serial arm.

    Not thread-safe: the ROS node serialises calls with a lock.

    Args:
        settings: Validated parameters.
        urdf_xml: The robot description (URDF string).

    Raises:
        KinematicsError: The URDF lacks a configured frame or joint.
        SettingsError: A parameter does not fit the model (e.g. the posture's length).
    """

    def __init__(self, settings: JogSettings, urdf_xml: str) -> None:
        self.settings = settings
        self.model = ArmModel(
            urdf_xml,
            settings.ee_frame_name,
            settings.joint_names,
            settings.joint_limits,
            settings.default_max_acceleration,
        )
        if not self.model.has_frame(settings.planning_frame):
            raise KinematicsError(
                f"planning_frame {settings.planning_frame!r} is not a frame of the robot model"
            )
        model_names = self.model.joint_names
        n = self.nv = self.model.nv
        if n < 6:
            raise KinematicsError(
                f"jog_arm needs at least 6 controlled joints to follow 6-D twists, got {list(model_names)}"
            )
        #: Joint order of every array given to and returned by this class.
        self.joint_names: tuple[str, ...] = settings.joint_names or model_names
        # _to_user[i]: model index of user joint i.
        self._to_user = np.array([model_names.index(name) for name in self.joint_names], dtype=np.intp)
        self._to_user_list = self._to_user.tolist()
        self._identity_order = self._to_user_list == list(range(n))
        self._period = settings.pub_period
        # With publish_on_command a step lasts until the next twist, not pub_period: nothing to straighten.
        self._straighten_step = math.inf if settings.publish_on_command else _STRAIGHTEN_STEP
        self.limiter = JointLimiter(
            self.model.lower,
            self.model.upper,
            self.model.max_velocity,
            self.model.max_acceleration,
            settings.joint_limit_margin,
            settings.joint_limit_slowdown_width,
            settings.pub_period,
        )
        # Continuous joints without position limits: whole turns apart is the same posture for them.
        self._turning = [
            i
            for i, continuous in enumerate(self.model.continuous)
            if continuous and math.isinf(self.model.lower[i]) and math.isinf(self.model.upper[i])
        ]
        self._filter = LowPassFilter(settings.low_pass_filter_coeff, 6)  # on the twist
        self._x_filtered = np.zeros(6)
        self._from_commanded = settings.integrate_from == "commanded"
        self._posture_fixed = bool(settings.nullspace_posture)
        posture = np.zeros(n)
        if self._posture_fixed:
            if len(settings.nullspace_posture) != n:
                raise SettingsError(
                    f"jog_arm_server/nullspace_posture has {len(settings.nullspace_posture)} values "
                    f"for {n} joints"
                )
            posture[self._to_user] = settings.nullspace_posture
        self._ns_gain = settings.nullspace_gain
        # gain x posture, so the pull gain·(posture - q) costs two vector operations per cycle.
        self._gain_posture = self._ns_gain * posture
        self._redundant = n > 6 and settings.nullspace_gain > 0.0
        if settings.command_in_type == "unitless":
            self._unit_scales = (float(settings.scale_linear), float(settings.scale_rotational))
        else:
            self._unit_scales = (1.0, 1.0)
        self._damping2 = settings.pinv_damping**2
        self._damping_threshold = settings.pinv_damping_threshold
        self._inv_length = 1.0 / settings.singularity_length_scale
        self._row_weights = np.array([self._inv_length] * 3 + [1.0] * 3)
        self._jjt = np.zeros((6, 6))
        self._displacement = np.zeros(6)
        self._eig = eigenpy.SelfAdjointEigenSolver(6)
        self._llt = eigenpy.LLT(6)
        self._eye6 = np.eye(6)
        self._eig_only = eigenpy.SelfAdjointEigenSolver(6)

        # State, model order. Joint vectors are float lists (faster than numpy at this size), except
        # the reference configuration Pinocchio reads.
        self._q_meas = [0.0] * n
        self._have_state = False
        self._state_time: float | None = None  # receive time of the joint state; None: not tracked
        self._drop_reason = ""  # why the last command was dropped (shown while there is none)
        self._suspended = ""  # why commands are refused for now (e.g. the ROS master is lost)
        self._q_cmd = [0.0] * n
        self._q_ref = np.zeros(n)
        self._dq_out = [0.0] * n
        self._twist = np.zeros(6)  # command, SI units, in its own frame
        self._twist_weighted = np.zeros(6)  # in root axes, linear part divided by singularity_length_scale
        self._frames: dict[str, _Frame] = {}
        self._cmd_frame: _Frame | None = None
        self._cmd_time: float | None = None
        self._cmd_zero = True
        self._rejected = ""
        self._paused = False
        self._running = False  # True from motion start until the final zero command was repeated
        self._filter_live = False
        self._zero_sent = settings.num_outgoing_halt_msgs_to_publish  # silent until the first command
        self._names_cache: tuple[tuple[str, ...], list[int]] = ((), [])
        self._zeros = (0.0,) * n
        self._out = JogOutput(n)
        self._geom = _Geometry()

    # --- inputs ---------------------------------------------------------------------------------------

    def set_joint_state(self, positions: Sequence[float], now: float | None = None) -> None:
        """Sets the measured joint positions [rad], in `joint_names` order, received at `now` [s] (None: its
        age is not checked).

        Raises:
            ValueError: Wrong length or a non-finite value (the previous state is kept).
        """
        values = [float(v) for v in positions]
        if len(values) != self.nv or not all(math.isfinite(v) for v in values):
            raise ValueError(f"joint state must be {self.nv} finite positions for {list(self.joint_names)}")
        self._store_measured(values, now)

    def set_joint_state_named(
        self, names: Sequence[str], positions: Sequence[float], now: float | None = None
    ) -> bool:
        """Sets the measured positions from a JointState-like (names, positions) pair received at `now` [s].

        Extra joints are ignored. Returns False, keeping the previous state, if a controlled joint is
        missing or a value is not finite.
        """
        key = tuple(names)
        cached_names, index = self._names_cache
        if key != cached_names:
            lookup = {name: i for i, name in enumerate(key)}
            if any(name not in lookup for name in self.joint_names):
                return False
            index = [lookup[name] for name in self.joint_names]
            self._names_cache = (key, index)
        if len(positions) != len(key):
            return False
        values = [float(positions[i]) for i in index]
        if not all(math.isfinite(v) for v in values):
            return False
        self._store_measured(values, now)
        return True

    def _store_measured(self, values: list[float], now: float | None) -> None:
        self._state_time = now
        if self._identity_order:
            self._q_meas = values
        else:
            q = [0.0] * self.nv
            for user_index, model_index in enumerate(self._to_user_list):
                q[model_index] = values[user_index]
            self._q_meas = q
        self._have_state = True

    def has_frame(self, name: str) -> bool:
        """True if commands in frame `name` can be resolved (model frame or added with :meth:`add_frame`)."""
        return self._resolve_frame(name) is not None

    def add_frame(self, name: str, parent: str, rotation: np.ndarray) -> None:
        """Makes a frame the model does not know usable for commands, fixed relative to a model frame.

        Args:
            name: New frame name.
            parent: A frame of the model.
            rotation: 3x3 rotation taking vectors in `name` to `parent` (the rotation of `name` in `parent`).

        Raises:
            KinematicsError: `parent` is unknown.
            ValueError: `rotation` is not a rotation matrix.
        """
        base = self._resolve_frame(parent.lstrip("/"))
        if base is None:
            raise KinematicsError(f"{parent!r} is not a frame of the robot model")
        rot = np.array(rotation, dtype=float)
        if rot.shape != (3, 3) or not np.allclose(rot @ rot.T, np.eye(3), atol=1e-6):
            raise ValueError(f"rotation of frame {name!r} must be a 3x3 rotation matrix")
        extra = rot if base.extra is None else base.extra @ rot
        static = None if base.static is None else base.static @ rot
        self._frames[name.lstrip("/")] = _Frame(base.frame_id, static, base.on_chain, extra)

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
        if self._paused:
            return CommandResult(False, "paused: commands are ignored until resume")
        if self._suspended:
            return CommandResult(False, f"suspended: {self._suspended}")
        reason = ""
        if len(twist) != 6:
            reason = f"a twist has 6 components, got {len(twist)}"
        elif not all(map(math.isfinite, twist)):
            reason = f"non-finite value in twist {list(twist)}"
        elif self.settings.command_in_type == "unitless" and any(abs(v) > 1.0 for v in twist):
            reason = f"unitless twist components must be within [-1, 1], got {list(twist)}"
        if not reason:
            resolved = self._resolve_frame((frame or self.settings.default_cmd_frame).lstrip("/"))
            if resolved is None:
                reason = f"unknown frame {frame!r}: not in the robot model nor added"
        if reason:
            self._rejected = reason
            return CommandResult(False, reason)
        assert resolved is not None  # no reason: the frame resolved
        self._rejected = ""
        # Plain floats: at this size numpy's per-call overhead dominates, more so with cold caches.
        lin, rot = self._unit_scales
        vx, vy, vz, wx, wy, wz = twist
        vx, vy, vz, wx, wy, wz = vx * lin, vy * lin, vz * lin, wx * rot, wy * rot, wz * rot
        self._twist[:] = (vx, vy, vz, wx, wy, wz)
        self._cmd_zero = not any(twist)
        self._cmd_frame = resolved
        rows = resolved.static_rows
        if rows is not None:  # rotate once, not every cycle
            (a, b, c), (d, e, f), (g, h, i) = rows
            k = self._inv_length
            self._twist_weighted[:] = (
                (a * vx + b * vy + c * vz) * k,
                (d * vx + e * vy + f * vz) * k,
                (g * vx + h * vy + i * vz) * k,
                a * wx + b * wy + c * wz,
                d * wx + e * wy + f * wz,
                g * wx + h * wy + i * wz,
            )
        self._cmd_time = now
        self._drop_reason = ""
        return _ACCEPTED

    def drop_command(self, reason: str) -> None:
        """Forgets the current command (its source vanished): the arm decelerates to rest at once instead of
        after `incoming_cmd_timeout`; the next command moves it again."""
        self._cmd_time = None
        self._cmd_zero = True
        self._drop_reason = reason

    def clock_jumped(self, description: str) -> None:
        """The clock jumped: the command's and the joint state's ages are unknown, so the command is dropped
        and the arm halts until a joint state received after the jump (then the next command moves it)."""
        self.drop_command(f"{description}: command dropped")
        if self._state_time is not None:
            self._state_time = -math.inf

    def suspend(self, reason: str) -> None:
        """Decelerates to rest and refuses commands until :meth:`unsuspend` (e.g. the master is lost)."""
        self._suspended = reason
        self.drop_command(reason)

    def unsuspend(self) -> None:
        """Accepts commands again; the arm stays at rest until the next one."""
        if self._suspended and self._drop_reason == self._suspended:
            self._drop_reason = ""
        self._suspended = ""

    def pause(self) -> None:
        """Stops (smoothly) and ignores commands until :meth:`resume`."""
        self._paused = True

    def resume(self) -> None:
        """Accepts commands again; motion restarts with the next command (the old one is dropped)."""
        self._paused = False
        self._cmd_time = None
        self._cmd_zero = True

    @property
    def measured(self) -> list[float] | None:
        """The last measured joint positions in model order (a new list per joint state; do not modify),
        None before the first."""
        return self._q_meas if self._have_state else None

    @property
    def paused(self) -> bool:
        """Whether :meth:`pause` is in effect."""
        return self._paused

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
            The shared :class:`JogOutput` (overwritten by the next call).
        """
        out = self._out
        if not self._have_state:
            out.publish = False
            out.status = StatusCode.NO_JOINT_STATE
            out.message = "no joint state received yet"
            out.speed_scale = 0.0
            return out
        # 1. Reference configuration (plain float lists: cheaper than numpy for 6-7 values).
        q_ref, resynced = self._reference()
        status, message = self._command_state(now)
        follow = status == StatusCode.NO_WARNING and not self._cmd_zero
        if not follow and not any(self._dq_out):
            return self._hold(q_ref, status, message)
        # 2.-5. Joint velocity for the twist (zero when there is nothing to follow).
        if follow:
            dq, condition, s_sing = self._follow(q_ref)
            dq = self._straighten(q_ref, dq)
        else:
            dq, condition, s_sing = self._no_follow(q_ref)
        # 6. Position, velocity and acceleration limits.
        dq_new, s_pos, s_vel = self._limit(q_ref, dq, follow)
        # 7. Integrate over the publish period.
        q_cmd = self._integrate(q_ref, dq_new)

        out.condition_number = condition
        if follow:
            self._zero_sent = 0
            status, message = self._motion_status(condition, s_sing, s_pos, s_vel)
            out.speed_scale = s_sing * s_pos * s_vel
        else:
            out.speed_scale = 0.0
            if not any(dq_new):
                self._zero_sent = 1
            if not message:
                message = "stopping"
        if resynced:
            message += " (re-synced to the measured joint state: tracking error above max_tracking_error)"
        out.positions = self._user_order(q_cmd)
        out.velocities = self._user_order(dq_new)
        out.publish = True
        out.status = status
        out.message = message
        return out

    def _command_state(self, now: float) -> tuple[StatusCode, str]:
        """Whether there is a command to follow now: NO_WARNING, or the reason there is none."""
        settings = self.settings
        state_time = self._state_time
        if self._paused:
            return StatusCode.PAUSED, "paused"
        if self._suspended:
            return StatusCode.PAUSED, f"suspended: {self._suspended}"
        if state_time is not None and now - state_time > settings.joint_state_timeout:
            message = (
                f"no joint state for {now - state_time:.3f} s (joint_state_timeout): stopping"
                if state_time > -math.inf
                else "waiting for a joint state received after the clock jump"
            )
            return StatusCode.STALE_JOINT_STATE, message
        if self._rejected:
            return StatusCode.INVALID_COMMAND, f"command rejected: {self._rejected}"
        if self._cmd_time is None:
            return StatusCode.STALE_COMMAND, self._drop_reason or "no command received yet"
        if now - self._cmd_time > settings.incoming_cmd_timeout:
            age = now - self._cmd_time
            return StatusCode.STALE_COMMAND, f"no command for {age:.3f} s (incoming_cmd_timeout)"
        return StatusCode.NO_WARNING, "zero command" if self._cmd_zero else ""

    def _start_running(self, q_arr: np.ndarray) -> None:
        if not self._running:
            self._running = True
            if not self._posture_fixed:
                np.multiply(q_arr, self._ns_gain, out=self._gain_posture)

    def _no_follow(self, q_ref: list[float]) -> tuple[list[float], float, float]:
        """Decelerating with nothing to follow: target zero (the condition number still reported)."""
        geometry = self._geometry(q_ref)
        self._start_running(geometry.q_arr)
        self._filter_live = False
        return [0.0] * self.nv, geometry.condition, 1.0

    def _follow(self, q_ref: list[float]) -> tuple[list[float], float, float]:
        """Stages 2-5: the filtered joint velocity for the twist, the condition number and the singularity
        scale applied."""
        settings = self.settings
        # 2. Jacobian, condition number, factorised damped J·Jᵀ (computed ahead by prefetch() if it could).
        geometry = self._geometry(q_ref)
        q_arr, J, condition = geometry.q_arr, geometry.J, geometry.condition
        self._start_running(q_arr)
        # 3. Twist in root axes (the joint velocity for it: `_solve`).
        x = self._twist_weighted
        frame = self._cmd_frame
        assert frame is not None  # a command is being followed
        if frame.static is None:
            rot = self.model.frame_rotation(frame.frame_id, None if frame.on_chain else q_arr)
            if frame.extra is not None:
                rot = rot @ frame.extra
            np.dot(rot, self._twist[:3], out=x[:3])
            np.dot(rot, self._twist[3:], out=x[3:])
            x *= self._row_weights
        # 4. Singularity: scale only motion that makes the condition number grow (judged on the unfiltered
        # joint velocity, so the first cycle that backs out is not slowed).
        s_sing = 1.0
        if condition > settings.singularity_threshold:
            toward = self._predicted_condition(q_arr, self._solve(J, x, q_arr, 1.0)) > condition
            s_sing = singularity_scale(
                condition, settings.singularity_threshold, settings.hard_stop_singularity_threshold, toward
            )
        # 5. Low-pass filter on the scaled twist (root axes), started from the twist of the current output so
        # there is no start-up jump. Filtering joint velocities instead blends J⁺ of past configurations,
        # which moves the tip sideways while the Jacobian changes (2 mm over 15 cm at 20 Hz, 7 joints).
        if not self._filter_live:
            self._filter.reset((J @ np.asarray(self._dq_out)).tolist())
            self._filter_live = True
        xf = self._x_filtered
        xf[:] = self._filter.filter((x * s_sing).tolist() if s_sing != 1.0 else x.tolist())
        return self._solve(J, xf, q_arr, s_sing).tolist(), condition, s_sing

    def _solve(self, J: np.ndarray, x: np.ndarray, q_arr: np.ndarray, scale: float) -> np.ndarray:
        """dq = J⁺x with the damped pseudo-inverse J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹ (Cholesky solve); on a redundant arm
        plus the null-space pull toward the posture, scaled by `scale`: J⁺x + (I - J⁺J)·pull =
        J⁺(x - J·pull) + pull."""
        llt = self._llt
        if not self._redundant:
            return J.T @ llt.solve(x)
        pull = (self._gain_posture - self._ns_gain * q_arr) * scale
        dq_arr = J.T @ llt.solve(x - J @ pull)
        dq_arr += pull
        return dq_arr

    def _limit(self, q_ref: list[float], dq: list[float], follow: bool) -> tuple[list[float], float, float]:
        """Stage 6: position, velocity, then acceleration limits, each scaling the whole vector; the new
        output velocity with the position and velocity scales."""
        limiter = self.limiter
        s_pos = limiter.position_scale(q_ref, dq)
        s_vel = (
            limiter.velocity_scale(dq) if s_pos == 1.0 else limiter.velocity_scale([v * s_pos for v in dq])
        )
        scale = s_pos * s_vel
        if scale < 1.0:
            dq = [v * scale for v in dq]
        dq_new, limited = limiter.limit_acceleration(self._dq_out, dq)
        if limited:  # slowing down slower than asked might cross a stop: position beats acceleration
            guard = limiter.step_scale(q_ref, dq_new)
            if guard < 1.0:
                dq_new = [v * guard for v in dq_new]
        if not follow and max(map(abs, dq_new)) < 1e-9:
            dq_new = [0.0] * self.nv
        self._dq_out = dq_new
        return dq_new, s_pos, s_vel

    def _integrate(self, q_ref: list[float], dq: list[float]) -> list[float]:
        """Stage 7: positions = reference + velocity x pub_period."""
        period = self._period
        self._q_cmd = q_cmd = [q + v * period for q, v in zip(q_ref, dq, strict=True)]
        return q_cmd

    def _straighten(self, q_ref: list[float], dq: list[float]) -> list[float]:
        """The joint velocity whose straight step over the period ends where the twist J(q_ref)·dq, held that
        long, takes the tip: a straight step in joint space moves the tip on a curve (at 20 Hz a 7-joint
        follower drifted 3.6 mm sideways over 15 cm). One Newton step with the damped pseudo-inverse at
        `q_ref`; a correction of second order (a few percent of the step), before the limits."""
        period = self._period
        if max(map(abs, dq)) * period <= self._straighten_step:
            return dq
        g = self._geometry(q_ref)
        dq_arr = np.asarray(dq)
        q_end = g.q_arr + dq_arr * period
        error = self.model.tip_displacement(g.q_arr, q_end, self._displacement)
        error[:3] *= self._inv_length
        error -= g.J @ dq_arr * period
        correction = (g.J.T @ self._llt.solve(error)) / period
        if np.max(np.abs(correction)) > _STRAIGHTEN_LIMIT * np.max(np.abs(dq_arr)):
            return dq  # not second order: a step too long for one Newton step to be right
        dq_arr -= correction
        return dq_arr.tolist()

    def prefetch(self) -> None:
        """Computes the next cycle's twist-independent part now (Jacobian, condition number, factorisation),
        so the next :meth:`step`, if its reference configuration is still this one, only solves for the
        twist: call it after publishing, off the path from twist to command."""
        if self._have_state and self._running:
            self._geometry(self._reference()[0])

    def _reference(self) -> tuple[list[float], bool]:
        """(reference configuration of the next step, whether it is a re-sync to the measured state)."""
        q_meas = self._q_meas
        if self._running and self._from_commanded:
            q_ref = self._q_cmd
            limit = self.settings.max_tracking_error
            if limit > 0.0 and max(map(abs, map(operator.sub, q_meas, q_ref))) > limit:
                # A driver may wrap a continuous joint's angle while the command goes on unwrapped.
                if not self._turning or self._wrapped_error(q_meas, q_ref) > limit:
                    return q_meas, True
            return q_ref, False
        return q_meas, False

    def _wrapped_error(self, q_meas: list[float], q_ref: list[float]) -> float:
        """Largest |measured - reference|, whole turns of the continuous joints taken out."""
        error = [abs(m - r) for m, r in zip(q_meas, q_ref, strict=True)]
        for i in self._turning:
            error[i] = abs(math.remainder(q_meas[i] - q_ref[i], math.tau))
        return max(error)

    def _geometry(self, q_ref: list[float]) -> _Geometry:
        """The twist-independent part of a cycle at `q_ref`, reused while `q_ref` does not change.

        Also leaves the placements of the tip's chain at `q_ref` in the model's data (see ArmModel.jacobian);
        whatever else moves the data invalidates this.
        """
        g = self._geom
        if g.valid and g.q == q_ref:
            return g
        q_arr = self._q_ref
        q_arr[:] = q_ref
        # The eigenvalues of J·Jᵀ are the squared singular values (eigenpy: ~2 µs).
        J = self.model.jacobian(q_arr)
        J[:3] *= self._inv_length
        A = np.dot(J, J.T, out=self._jjt)
        self._eig.compute(A, _EIGENVALUES_ONLY)
        sigma2 = self._eig.eigenvalues()  # ascending; a view, valid until the next compute
        s2_min, s2_max = float(sigma2[0]), float(sigma2[-1])
        # Damped pseudo-inverse J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹: λ grows as the smallest singular value falls.
        s_min = math.sqrt(max(s2_min, 0.0))
        if s_min < self._damping_threshold:
            ratio = s_min / self._damping_threshold
            A += self._eye6 * (self._damping2 * (1.0 - ratio * ratio) + _DAMPING_FLOOR)
        llt = self._llt
        llt.compute(A)
        if llt.info() != eigenpy.ComputationInfo.Success:  # numerically singular: damp harder
            A += self._eye6 * (_DAMPING_FLOOR + 1e-6 * s2_max)
            llt.compute(A)
        g.q = list(q_ref)
        g.q_arr, g.J = q_arr, J
        g.condition = math.sqrt(s2_max / s2_min) if s2_min > 0.0 else math.inf
        g.valid = True
        return g

    def _user_order(self, values: list[float]) -> tuple[float, ...]:
        """Model-order `values` as a user-order tuple."""
        if self._identity_order:
            return tuple(values)
        return tuple([values[i] for i in self._to_user_list])

    def _hold(self, q_ref: list[float], status: StatusCode, message: str) -> JogOutput:
        """Cycle at rest: repeat the zero command a few times, then fall silent."""
        out = self._out
        self._filter_live = False
        if self._running:
            self._q_cmd = q_ref
        if self._zero_sent < self.settings.num_outgoing_halt_msgs_to_publish:
            self._zero_sent += 1
            out.publish = True
        else:
            out.publish = False
            self._running = False
        out.positions = self._user_order(q_ref)
        out.velocities = self._zeros
        out.status = status
        out.message = message or "at rest"
        out.speed_scale = 0.0
        return out

    def _predicted_condition(self, q: np.ndarray, dq: np.ndarray) -> float:
        """Condition number a small step along `dq` would give (overwrites the model's data)."""
        norm = max(map(abs, dq.tolist()))
        if norm == 0.0:
            return 0.0
        self._geom.valid = False
        J = self._weighted_jacobian(q + dq * (_PREDICTION_STEP / norm))
        self._eig_only.compute(J @ J.T, _EIGENVALUES_ONLY)
        sigma2 = self._eig_only.eigenvalues()
        return math.sqrt(float(sigma2[-1]) / float(sigma2[0])) if sigma2[0] > 0.0 else math.inf

    def _weighted_jacobian(self, q: np.ndarray) -> np.ndarray:
        """Tip Jacobian at `q` with its linear rows divided by the characteristic length (a fresh array)."""
        J = self.model.jacobian(q)
        J[:3] *= self._inv_length
        return J

    def _motion_status(
        self, condition: float, s_sing: float, s_pos: float, s_vel: float
    ) -> tuple[StatusCode, str]:
        if s_sing == 0.0:
            return StatusCode.HALT_FOR_SINGULARITY, f"halted: condition number {condition:.1f} at hard stop"
        if s_pos == 0.0:
            return StatusCode.HALT_FOR_JOINT_LIMIT, "halted: a joint is at its position limit margin"
        if s_sing < 1.0:
            return (
                StatusCode.DECELERATE_FOR_SINGULARITY,
                f"slowing down near a singularity: condition number {condition:.1f}",
            )
        if s_pos < 1.0:
            return StatusCode.DECELERATE_FOR_JOINT_LIMIT, "slowing down near a joint position limit"
        if s_vel < 1.0:
            return StatusCode.JOINT_VELOCITY_SCALED, "command scaled to the joint velocity limits"
        return StatusCode.NO_WARNING, "moving"

    # --- outputs and queries --------------------------------------------------------------------------

    def trajectory_points(self, count: int) -> list[tuple[tuple[float, ...], tuple[float, ...], float]]:
        """Points (positions, velocities, time_from_start [s]) of the last output, for a JointTrajectory.

        The first point is the cycle's output; later ones (simu mode) extrapolate at its velocity, kept
        inside the position limits minus the margin, for controllers that drop points already in the past.
        """
        out = self._out
        points = [(out.positions, out.velocities, self._period)]
        if count > 1:
            q = np.array(out.positions)
            v = np.array(out.velocities)
            lower = np.minimum(self.limiter.lower_stop[self._to_user], q)
            upper = np.maximum(self.limiter.upper_stop[self._to_user], q)
            for k in range(2, count + 1):
                ahead = np.clip(q + v * (self._period * (k - 1)), lower, upper)
                points.append((tuple(ahead.tolist()), out.velocities, self._period * k))
        return points

    def eef_pose(self, positions: Sequence[float] | None = None) -> pin.SE3:
        """Pose of `ee_frame_name` in `planning_frame` at `positions` (user order) or the last reference."""
        q = self._q_ref.copy() if positions is None else np.empty(self.nv)
        if positions is not None:
            q[self._to_user] = np.asarray(positions, dtype=float)
        self._geom.valid = False  # frame_pose moves the model's data
        return self.model.frame_pose(q, self.settings.ee_frame_name, self.settings.planning_frame)

    def _resolve_frame(self, name: str) -> _Frame | None:
        frame = self._frames.get(name)
        if frame is None and self.model.has_frame(name):
            fid = self.model.frame_id(name)
            parent_joint = self.model.model.frames[fid].parentJoint
            static = self.model.model.frames[fid].placement.rotation.copy() if parent_joint == 0 else None
            frame = _Frame(fid, static, self.model.moves_with_tip_chain(fid), None)
            self._frames[name] = frame
        return frame
