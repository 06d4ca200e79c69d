"""The simulation core: step a position-controlled arm with a wrist F/T sensor, no ROS.

Conventions:
  * Joint vectors are in :attr:`Simulation.joint_names` order (URDF tree order); use
    :meth:`Simulation.joint_indices` to map a message's name order.
  * The MuJoCo world frame is the robot's base frame (URDF root link); poses are expressed in it.
  * :meth:`Simulation.wrench` is the wrench the environment (gravity, contacts, pushes) exerts on the tool,
    expressed in the F/T sensor frame, torque about the sensor origin, as ``[fx, fy, fz, tx, ty, tz]``
    [N, Nm] -- what a wrist sensor shows after its driver, untared: at rest it reads the tool's weight
    (``mass * g`` along world -Z once rotated to the world), and pushing the tool along +Z_world gives a
    positive world-Z force. It includes the tool's inertial force ``-m a`` while the arm accelerates.
  * The kinematic state (qpos, poses) is always current; the wrench refers to the last completed step.

Commands (the last one wins; each replaces the previous mode):
  * :meth:`set_position_targets`: hold these joint positions.
  * :meth:`set_velocity_targets`: integrate a position target at this velocity (clamped at the limits),
    fed to the servo with the velocity as feed-forward, so the velocity is tracked without lag.
  * :meth:`set_trajectory`: follow points (cubic Hermite with velocities, linear without) from the current
    target, then hold the last point.
The servo limits the setpoint's rate to the URDF velocity limits and its torque to the URDF effort limits.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import mujoco
import numpy as np
from compliant_common.errors import StackError

from mujoco_driver.config import SceneConfig
from mujoco_driver.scene import SceneModel, build_scene

__all__ = ["CommandError", "Simulation", "TrajectoryPoint", "step_arms"]

MODE_POSITION, MODE_VELOCITY, MODE_TRAJECTORY = "position", "velocity", "trajectory"
# [1/s] Trajectory mode: the setpoint closes a position gap to the interpolated path with this rate (a 33 ms
# time constant), on top of the path's own velocity.
TRACKING_GAIN = 30.0


class CommandError(StackError):
    """Raised for a malformed command (wrong length, NaN, unknown joint, bad timing); state is unchanged."""


class TrajectoryPoint(NamedTuple):
    """One trajectory point, as in trajectory_msgs/JointTrajectoryPoint.

    Attributes:
        positions: Joint positions [rad or m], in joint_names order.
        velocities: Joint velocities, or None to interpolate linearly.
        time_from_start: Time of the point after the trajectory's start [s].
    """

    positions: Sequence[float] | np.ndarray
    velocities: Sequence[float] | np.ndarray | None
    time_from_start: float


class Simulation:
    """A MuJoCo scene of the arm on its table, stepped on demand (real-time pacing is the caller's job).

    Args:
        urdf_xml: The robot description (what the ``robot_description`` parameter holds).
        scene_cfg: A :class:`SceneConfig` or the mapping it is read from (``sim.yaml``).
        mesh_cache: Directory for meshes converted to a format MuJoCo reads (see ``mujoco_driver.meshes``);
            None = the default cache.

    Raises:
        ConfigError: On bad scene settings.
        SceneError: If the URDF and the settings do not make a valid model.
    """

    def __init__(
        self, urdf_xml: str, scene_cfg: SceneConfig | Mapping[str, Any], mesh_cache: str | None = None
    ) -> None:
        cfg = scene_cfg if isinstance(scene_cfg, SceneConfig) else SceneConfig.from_dict(scene_cfg)
        scene = build_scene(urdf_xml, cfg, mesh_cache)
        self._bind(cfg, scene, mujoco.MjData(scene.model), None)
        self.reset()

    @classmethod
    def in_world(cls, world: Any, cfg: SceneConfig, scene: SceneModel, base: np.ndarray) -> Simulation:
        """One arm of a world of several (mujoco_driver.cell.World, which steps and resets them all).

        Args:
            world: The world; this arm's :meth:`step` steps it.
            cfg: The arm's scene settings.
            scene: The arm's indices in the world's model (its names carry ``scene.prefix``).
            base: The arm's base frame in the world: x, y, z [m], qw, qx, qy, qz.
        """
        sim = cls.__new__(cls)
        sim._bind(cfg, scene, world.data, base)
        sim._world = world
        return sim

    def _bind(
        self, cfg: SceneConfig, scene: SceneModel, data: mujoco.MjData, base: np.ndarray | None
    ) -> None:
        self.config = cfg
        self.scene = scene
        self.model = scene.model
        self.data = data
        self._world: Any = None
        # The base frame in MuJoCo's world: None when they are one (an arm alone); poses, the sensor's
        # rotation and pushes are turned between them.
        self._base = None if base is None else (np.asarray(base[:3], float), np.asarray(base[3:], float))
        self._base_R, self._base_conj = np.eye(3), np.zeros(4)
        if base is not None:
            quat = np.asarray(base[3:], float)
            mujoco.mju_quat2Mat(self._base_R.reshape(9), quat)
            mujoco.mju_negQuat(self._base_conj, quat)
        self.joint_names: tuple[str, ...] = tuple(self.scene.joint_names)
        # The joints velocity commands address (every joint but the held ones), in joint_names order.
        self.arm_joint_names: tuple[str, ...] = tuple(self.joint_names[i] for i in self.scene.arm_index)
        n = len(self.joint_names)
        self._arm_qd = np.zeros(n)  # a velocity command of the arm joints, held joints at 0
        self._dt = float(self.model.opt.timestep)
        self._index = {name: i for i, name in enumerate(self.joint_names)}
        sc = self.scene
        parents = self.model.body_parentid
        self._measured = {b for b in range(self.model.nbody) if self._below(b, sc.sensor_body, parents)}
        self._pos_ctrl, self._vel_ctrl, self._ff_ctrl = sc.ctrl_adr, sc.ctrl_adr + 1, sc.ctrl_adr + 2
        # The servos' controls as a (joint, [position, velocity, torque]) view when the scene lays them out
        # that way (an arm alone: joint by joint, the dofs in joint order): strided copies instead of fancy
        # indexing, ~5 us less per step.
        regular = (self.model.nu == 3 * n and np.array_equal(sc.ctrl_adr, 3 * np.arange(n))
                   and np.array_equal(sc.dof_adr, np.arange(n)))
        self._ctrl3 = self.data.ctrl.reshape(n, 3) if regular else None
        # Preallocated work arrays. _goal is the position command; _q_target/_qd_target the servo setpoint,
        # which moves towards the command no faster than the velocity limits.
        self._goal = np.zeros(n)
        self._q_target = np.zeros(n)
        self._qd_target = np.zeros(n)
        self._q_desired = np.zeros(n)
        self._qd_desired = np.zeros(n)
        self._qd_command = np.zeros(n)
        self._correction = np.zeros(n)
        self._scratch = np.zeros(n)
        self._two_accel = 2.0 * sc.max_acceleration
        self._max_accel = sc.max_acceleration
        self._max_dv = self._max_accel * self.dt
        self._brake_dv = sc.max_deceleration * self.dt
        self._brakes = bool(np.any(sc.max_deceleration != sc.max_acceleration))
        self._dv_limit = self._max_dv.copy()
        self._slowing, self._not_past = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        self._speed = np.zeros(n)
        self._jacp = np.zeros((3, self.model.nv))
        self._payload_force = -sc.payload_mass * self.model.opt.gravity
        self._ff = np.zeros(self.model.nv)
        self._wrench = np.zeros(6)
        self._mode = MODE_POSITION
        self._traj: tuple[float, np.ndarray, np.ndarray, np.ndarray, bool] | None = None
        self._traj_seg = 0
        self._push_steps = 0
        self._push_wrench = np.zeros(6)
        self._push_world = np.zeros(6)
        self._rng = np.random.default_rng(cfg.wrench_noise.seed)

    @staticmethod
    def _below(body: int, root: int, parents: np.ndarray) -> bool:
        while body > 0 and body != root:
            body = parents[body]
        return body == root

    # ------------------------------------------------------------------ state
    @property
    def dt(self) -> float:
        """Simulation timestep [s]."""
        return float(self.model.opt.timestep)

    @property
    def time(self) -> float:
        """Simulated time since the last reset [s]."""
        return float(self.data.time)

    @property
    def qpos(self) -> np.ndarray:
        """Joint positions [rad or m] (a copy)."""
        return self.data.qpos[self.scene.qpos_adr]

    @property
    def qvel(self) -> np.ndarray:
        """Joint velocities [rad/s or m/s] (a copy)."""
        return self.data.qvel[self.scene.dof_adr]

    @property
    def effort(self) -> np.ndarray:
        """Servo torques (forces) applied at the joints [Nm or N] during the last step (a copy)."""
        return self.data.qfrc_actuator[self.scene.dof_adr]

    @property
    def position_targets(self) -> np.ndarray:
        """The joint position setpoint the servo is tracking (a copy)."""
        return self._q_target.copy()

    @property
    def mode(self) -> str:
        """Active command mode: "position", "velocity" or "trajectory"."""
        return self._mode

    @property
    def push_remaining(self) -> float:
        """Time left of the current push [s] (0 when none)."""
        return self._push_steps * self.dt

    @property
    def push_wrench(self) -> tuple[float, ...]:
        """The current push's force and torque (base frame), zeros when none."""
        return tuple(float(x) for x in self._push_wrench) if self._push_steps else (0.0,) * 6

    def joint_indices(self, names: Sequence[str]) -> np.ndarray:
        """Positions of ``names`` in :attr:`joint_names` (to reorder a message's arrays).

        Raises:
            CommandError: If a name is unknown.
        """
        try:
            return np.array([self._index[name] for name in names], dtype=int)
        except KeyError as exc:
            known = list(self.joint_names)
            raise CommandError(f"unknown joint {exc.args[0]!r}; joints are {known}") from None

    def wrench(self, out: np.ndarray | None = None) -> np.ndarray:
        """Wrench the environment exerts on the tool, in the sensor frame: [fx, fy, fz, tx, ty, tz] [N, Nm].

        Args:
            out: Optional 6-array to write into (avoids an allocation).

        Returns:
            ``out`` or a new array, with the configured Gaussian noise added.
        """
        result = self._wrench if out is None else out
        sensordata, sc = self.data.sensordata, self.scene
        # MuJoCo reports the force and torque the parent exerts on the sensor's subtree; the environment's
        # wrench on the tool is its opposite (static balance), which is what a wrist sensor reads.
        np.negative(sensordata[sc.force_adr:sc.force_adr + 3], out=result[:3])
        np.negative(sensordata[sc.torque_adr:sc.torque_adr + 3], out=result[3:])
        noise = self.config.wrench_noise
        if noise.force_std > 0.0:
            result[:3] += self._rng.normal(0.0, noise.force_std, 3)
        if noise.torque_std > 0.0:
            result[3:] += self._rng.normal(0.0, noise.torque_std, 3)
        return result.copy() if out is None else result

    def link_pose(self, body_id: int) -> tuple[np.ndarray, np.ndarray]:
        """Pose of a body in the base frame: (position [m], quaternion x, y, z, w)."""
        pos, quat = self.data.xpos[body_id].copy(), self.data.xquat[body_id]
        if self._base is not None:
            pos = self._base_R.T @ (pos - self._base[0])
            local = np.zeros(4)
            mujoco.mju_mulQuat(local, self._base_conj, quat)
            quat = local
        return pos, np.array([quat[1], quat[2], quat[3], quat[0]])

    def world_pose(
        self, pos: np.ndarray, quat: np.ndarray, out_pos: np.ndarray, out_quat: np.ndarray
    ) -> None:
        """A MuJoCo world pose (position, quaternion w, x, y, z) in the base frame, written into the outs."""
        if self._base is None:
            out_pos[:], out_quat[:] = pos, quat
            return
        np.subtract(pos, self._base[0], out=out_pos)
        out_pos[:] = self._base_R.T @ out_pos
        mujoco.mju_mulQuat(out_quat, self._base_conj, quat)

    def eef_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """End-effector frame (``links.eef``) in the base frame: (position [m], quaternion x, y, z, w)."""
        return self.link_pose(self.scene.eef_body)

    def sensor_rotation(self) -> np.ndarray:
        """Rotation matrix of the F/T sensor frame in the base frame (3x3 copy)."""
        return self._base_R.T @ self.data.site_xmat[self.scene.ft_site].reshape(3, 3)

    def tool_contacts(self) -> set[str]:
        """Names of the geoms (or their bodies, if unnamed) the sensor's subtree touches now."""
        model, data, measured = self.model, self.data, self._measured
        touched = set()
        for contact in data.contact[: data.ncon]:
            b1, b2 = model.geom_bodyid[contact.geom[0]], model.geom_bodyid[contact.geom[1]]
            other = contact.geom[1] if b1 in measured else contact.geom[0] if b2 in measured else -1
            if other >= 0:
                name = model.geom(other).name or model.body(model.geom_bodyid[other]).name
                prefix = self.scene.prefix  # this arm's own environment by its own names
                touched.add(name[len(prefix):] if prefix and name.startswith(prefix) else name)
        return touched

    def warnings(self) -> dict[str, int]:
        """MuJoCo warnings raised since the last reset, by name (empty when all is well)."""
        return {
            mujoco.mjtWarning(i).name: int(w.number) for i, w in enumerate(self.data.warning) if w.number > 0
        }

    # --------------------------------------------------------------- commands
    def _vector(self, values: Sequence[float] | np.ndarray, what: str) -> np.ndarray:
        try:
            array = np.asarray(values, dtype=float)
        except (TypeError, ValueError) as exc:
            raise CommandError(f"{what}: not a list of numbers: {values!r}") from exc
        if array.shape != self._q_target.shape:
            raise CommandError(f"{what}: expected {len(self.joint_names)} values, got shape {array.shape}")
        if not np.all(np.isfinite(array)):
            raise CommandError(f"{what}: values must be finite, got {array}")
        return array

    def set_position_targets(self, q: Sequence[float] | np.ndarray) -> None:
        """Hold joint positions ``q`` (clamped to the joint limits).

        Raises:
            CommandError: On a wrong length or non-finite values.
        """
        q = self._vector(q, "position targets")
        np.clip(q, self.scene.lower, self.scene.upper, out=self._goal)
        self._mode, self._traj = MODE_POSITION, None

    def set_velocity_targets(self, qd: Sequence[float] | np.ndarray) -> None:
        """Move the joints at ``qd`` until told otherwise (scaled down uniformly to the velocity limits).

        Raises:
            CommandError: On a wrong length or non-finite values.
        """
        qd = self._vector(qd, "velocity targets")
        ratio = np.max(np.abs(qd) / self.scene.velocity_limit)
        if ratio > 1.0:
            qd = qd / ratio
        self._qd_command[:] = qd
        self._mode, self._traj = MODE_VELOCITY, None

    def set_arm_velocity_targets(self, qd: np.ndarray) -> None:
        """:meth:`set_velocity_targets` for the arm joints (``arm_joint_names`` order); held joints stay.

        Raises:
            CommandError: On a wrong length or non-finite values.
        """
        if len(self.arm_joint_names) == len(self.joint_names):
            self.set_velocity_targets(qd)
            return
        if np.shape(qd) != (len(self.arm_joint_names),):
            raise CommandError(f"velocity targets: expected {len(self.arm_joint_names)} values (arm joints "
                               f"{list(self.arm_joint_names)}), got shape {np.shape(qd)}")
        self._arm_qd[self.scene.arm_index] = qd
        self.set_velocity_targets(self._arm_qd)

    def set_trajectory(self, points: Sequence[TrajectoryPoint], start_time: float | None = None) -> None:
        """Follow ``points`` from the current setpoint, starting at ``start_time`` (default: now).

        A point with time 0 replaces the current setpoint as the start. Positions are clamped to the limits.

        Raises:
            CommandError: On no points, a wrong length, non-finite values or times not strictly increasing.
        """
        if len(points) == 0:
            raise CommandError("trajectory: no points")
        try:
            times = np.array([float(p[2]) for p in points])
        except (TypeError, ValueError, IndexError) as exc:
            raise CommandError(f"trajectory: points are (positions, velocities, time): {exc}") from exc
        if not np.all(np.isfinite(times)) or times[0] < 0.0 or np.any(np.diff(times) <= 0.0):
            raise CommandError(f"trajectory: times must be finite, >= 0 and strictly increasing, got {times}")
        positions = np.array([np.clip(self._vector(p[0], f"trajectory point {i} positions"),
                                      self.scene.lower, self.scene.upper) for i, p in enumerate(points)])
        has_vel = all(p[1] is not None and len(p[1]) > 0 for p in points)
        velocities = np.zeros_like(positions)
        if has_vel:
            for i, point in enumerate(points):
                assert point[1] is not None  # has_vel
                velocities[i] = self._vector(point[1], f"trajectory point {i} velocities")
        if times[0] > 0.0:
            times = np.concatenate(([0.0], times))
            positions = np.vstack((self._q_target, positions))
            start_vel = self._qd_target if has_vel else np.zeros_like(self._q_target)
            velocities = np.vstack((start_vel, velocities))
        start = self.time if start_time is None else float(start_time)
        self._traj = (start, times, positions, velocities, has_vel)
        self._traj_seg = 0
        self._mode = MODE_TRAJECTORY

    def push(
        self, force: Sequence[float], torque: Sequence[float] = (0.0, 0.0, 0.0), duration: float = 1.0
    ) -> None:
        """Apply a force and torque (base/world frame, at the tool's centre of mass) for ``duration`` seconds.

        A new push replaces the one in progress; a zero duration cancels it.

        Raises:
            CommandError: On non-finite values or a negative duration.
        """
        try:
            wrench = np.concatenate((np.ravel(np.asarray(force, float)), np.ravel(np.asarray(torque, float))))
            duration = float(duration)
        except (TypeError, ValueError) as exc:
            raise CommandError(f"push: force, torque and duration must be numbers: {exc}") from exc
        if wrench.shape != (6,) or not np.all(np.isfinite(wrench)):
            raise CommandError(f"push: force and torque must be 3 finite values each, got {force}, {torque}")
        if not math.isfinite(duration) or duration < 0.0:
            raise CommandError(f"push: duration must be >= 0 s, got {duration}")
        self._push_steps = round(duration / self.dt)
        self._push_wrench[:] = wrench
        self._push_world[:3], self._push_world[3:] = self._base_R @ wrench[:3], self._base_R @ wrench[3:]
        self.data.xfrc_applied[self.scene.tool_body] = self._push_world if self._push_steps else 0.0

    def reset(self) -> None:
        """Back to the start pose at time 0, at rest, holding position, no push. An arm in a world goes back
        alone: the world's time and the other arms go on."""
        model, data = self.model, self.data
        if self._world is None:
            mujoco.mj_resetData(model, data)
        else:
            data.qvel[self.scene.dof_adr] = 0.0
            data.qacc_warmstart[self.scene.dof_adr] = 0.0
        self._reset_arm()
        mujoco.mj_forward(model, data)  # kinematics of the start pose, for the payload feed-forward
        self._write_controls()
        mujoco.mj_forward(model, data)  # sensors see the servo holding the start pose

    def _reset_arm(self) -> None:
        sc, data = self.scene, self.data
        data.qpos[sc.qpos_adr] = sc.start_pose
        data.xfrc_applied[sc.tool_body] = 0.0
        self._goal[:] = sc.start_pose
        self._q_target[:] = sc.start_pose
        self._qd_target[:] = 0.0
        self._qd_command[:] = 0.0
        self._mode, self._traj = MODE_POSITION, None
        self._push_steps = 0
        self._rng = np.random.default_rng(self.config.wrench_noise.seed)

    # ---------------------------------------------------------------- stepping
    def step(self, n: int = 1) -> None:
        """Advance ``n`` timesteps (an arm in a world: the whole world)."""
        if self._world is not None:
            self._world.step(n)
            return
        step_arms(self.model, self.data, (self,), n)

    def _before_step(self) -> None:
        self._update_setpoint()
        self._write_controls()
        if self._push_steps:  # every step: the viewer's sync() zeroes xfrc_applied (its mouse channel)
            self.data.xfrc_applied[self.scene.tool_body] = self._push_world

    def _after_step(self) -> None:
        if self._push_steps:
            self._push_steps -= 1
            if not self._push_steps:
                self.data.xfrc_applied[self.scene.tool_body] = 0.0

    def _write_controls(self) -> None:
        ctrl3 = self._ctrl3
        if ctrl3 is not None:
            ctrl3[:, 0] = self._q_target
            ctrl3[:, 1] = self._qd_target
            if self.config.servo.payload_feedforward:
                mujoco.mj_jacSubtreeCom(self.model, self.data, self._jacp, self.scene.sensor_body)
                np.dot(self._payload_force, self._jacp, out=self._ff)
                ctrl3[:, 2] = self._ff[:len(ctrl3)]  # = _ff[dof_adr]: the dofs lead, in joint order
            return
        ctrl = self.data.ctrl
        ctrl[self._pos_ctrl] = self._q_target
        ctrl[self._vel_ctrl] = self._qd_target
        if self.config.servo.payload_feedforward:
            # Torque that holds the payload's weight: -J_com^T (m g), like a controller's payload setting.
            mujoco.mj_jacSubtreeCom(self.model, self.data, self._jacp, self.scene.sensor_body)
            np.dot(self._payload_force, self._jacp, out=self._ff)
            ctrl[self._ff_ctrl] = self._ff[self.scene.dof_adr]

    def _update_setpoint(self) -> None:
        """Advance the servo setpoint (``_q_target``, ``_qd_target``) by one step, within the joint limits.

        In every mode the setpoint's velocity stays within the velocity limits and changes by at most
        ``max_acceleration * dt`` per step, as a robot controller's rate limiter does: a late or jumping
        command then gives a bounded acceleration (and a bounded inertial force on the wrist sensor)
        instead of a spike. In velocity and trajectory modes a joint slowing down may change by
        ``max_deceleration * dt``: a stop brakes as the robot can.
        Position mode: a velocity- and acceleration-limited profile to the goal (brakes in time to stop).
        Velocity mode: the commanded velocity, reached with the acceleration limit, integrated.
        Trajectory mode: the interpolated velocity plus a correction towards the interpolated position
        (linear near the path, never faster than the joint can still brake), acceleration-limited.
        """
        dt, q_t, qd_t = self._dt, self._q_target, self._qd_target
        vel, err = self._qd_desired, self._q_desired
        if self._mode == MODE_TRAJECTORY:
            self._sample_trajectory(self.time + dt, err, vel)  # may end it: then position mode below
        if self._mode == MODE_TRAJECTORY:
            np.subtract(err, q_t, out=err)
            fix, brake = self._correction, self._scratch
            np.abs(err, out=fix)
            np.multiply(fix, self._two_accel, out=brake)
            np.sqrt(brake, out=brake)
            fix *= TRACKING_GAIN
            np.minimum(fix, brake, out=fix)
            np.copysign(fix, err, out=fix)
            vel += fix
        elif self._mode == MODE_VELOCITY:
            vel[:] = self._qd_command
        else:
            # Fastest speed from which the joint can still stop on the goal: sqrt(2 a |e|).
            np.subtract(self._goal, q_t, out=err)
            np.sqrt(2.0 * self._max_accel * np.abs(err), out=vel)
            np.copysign(vel, err, out=vel)
        np.clip(vel, -self.scene.velocity_limit, self.scene.velocity_limit, out=vel)
        if self._mode == MODE_POSITION:
            np.clip(vel, qd_t - self._max_dv, qd_t + self._max_dv, out=qd_t)
        else:
            # Scale the velocity change as a whole, so that a catch-up keeps the direction of motion (and the
            # tool its Cartesian path) instead of the joints with the most to do lagging behind.
            limit = self._dv_limit
            if self._brakes:  # a joint slowing down (toward rest, not past it) may change at max_deceleration
                slowing, not_past, speed, scratch = self._slowing, self._not_past, self._speed, self._scratch
                np.multiply(vel, qd_t, out=scratch)
                np.greater_equal(scratch, 0.0, out=not_past)
                np.abs(vel, out=scratch)
                np.abs(qd_t, out=speed)
                np.less(scratch, speed, out=slowing)
                np.logical_and(slowing, not_past, out=slowing)
                np.copyto(limit, self._max_dv)
                np.copyto(limit, self._brake_dv, where=slowing)
            np.subtract(vel, qd_t, out=vel)
            np.abs(vel, out=self._scratch)
            self._scratch /= limit
            ratio = float(self._scratch.max())
            if ratio > 1.0:
                vel /= ratio
            qd_t += vel
        if self._mode == MODE_POSITION:
            # Snap onto the goal when this step reaches it at a speed the joint can drop in one step
            # (a faster arrival overshoots a little and comes back, as an acceleration-limited stop does).
            arrive = (np.abs(qd_t * dt) >= np.abs(err)) & (np.abs(qd_t) <= self._max_dv)
            q_t += qd_t * dt
            if arrive.any():
                q_t[arrive] = self._goal[arrive]
                qd_t[arrive] = 0.0
        else:
            q_t += qd_t * dt
            outside = (q_t < self.scene.lower) | (q_t > self.scene.upper)
            if outside.any():
                np.clip(q_t, self.scene.lower, self.scene.upper, out=q_t)
                qd_t[outside] = 0.0

    def _sample_trajectory(self, now: float, q: np.ndarray, qd: np.ndarray) -> None:
        """Desired position and velocity of the trajectory at time ``now``; ends it after its last point."""
        start, times, positions, velocities, has_vel = self._traj  # type: ignore[misc]
        t = now - start
        if t <= times[0]:
            q[:], qd[:] = positions[0], velocities[0]
            return
        if t >= times[-1]:
            q[:], qd[:] = positions[-1], 0.0
            self._goal[:] = positions[-1]
            self._mode, self._traj = MODE_POSITION, None
            return
        seg = self._traj_seg
        while times[seg + 1] < t:
            seg += 1
        self._traj_seg = seg
        h = times[seg + 1] - times[seg]
        s = (t - times[seg]) / h
        p0, p1 = positions[seg], positions[seg + 1]
        if not has_vel:
            q[:] = p0 + s * (p1 - p0)
            qd[:] = (p1 - p0) / h
            return
        v0, v1 = velocities[seg] * h, velocities[seg + 1] * h
        s2, s3 = s * s, s * s * s
        q[:] = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * v0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * v1
        qd[:] = ((6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * v0
                 + (-6 * s2 + 6 * s) * p1 + (3 * s2 - 2 * s) * v1) / h


def step_arms(model: mujoco.MjModel, data: mujoco.MjData, arms: Sequence[Simulation], n: int) -> None:
    """`n` timesteps of `data`, each of `arms` (an arm alone, or a cell's) following its own command."""
    for _ in range(n):
        for arm in arms:
            arm._before_step()
        mujoco.mj_step2(model, data)
        for arm in arms:
            arm._after_step()
        # Position stage for the new state, so poses and qpos always agree between calls.
        mujoco.mj_step1(model, data)
