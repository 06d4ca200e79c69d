"""Serial-arm kinematics from a URDF string with Pinocchio: EEF pose and Jacobian of the controlled joints.

Joints that are not controlled (grippers, a head, another arm, a mobile base, ...) are locked with
``pinocchio.buildReducedModel`` at their held position (``held_positions``; 0 clamped into the joint's limits
for the others), so the Jacobian has exactly one column per controlled joint. The model
and its data are built once; every query reuses them.

Frames: Jacobians are ``LOCAL_WORLD_ALIGNED`` at the tip frame, i.e. the velocity of the tip's origin and
the angular velocity, both with the axes of the model's root (``universe``) frame.

Continuous joints: Pinocchio models an unbounded revolute joint with two configuration values (cos, sin)
and one velocity, so its ``q`` is longer than ``v``. Every array this class takes or returns has ONE value
per controlled joint (the angle, as ``sensor_msgs/JointState`` carries it); :meth:`ArmModel.pin_q` turns
such an array into Pinocchio's ``q`` in a preallocated buffer. Angles of continuous joints are taken as
they come (unwrapped: 7.0 rad is fine), have no position limits (-inf, +inf) unless the configuration
sets some, and keep their velocity and acceleration limits.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pinocchio as pin
from compliant_common.errors import StackError
from compliant_common.typedefs import FloatArray

from jog_arm.settings import JointLimitOverride

__all__ = ["ArmModel", "KinematicsError"]


class KinematicsError(StackError):
    """The URDF cannot be parsed, or a frame or joint named in the configuration is not in it."""


class ArmModel:
    """Kinematic model of the controlled chain of a robot description.

    Args:
        urdf_xml: The URDF as a string (the `robot_description` parameter).
        tip_frame: Frame whose motion is commanded (a link or fixed-joint frame of the URDF).
        joint_names: Controlled joints in the order the caller uses; empty = every joint from the root to
            `tip_frame`. The model's own order is the kinematic order; arrays in this class use it, one
            value per joint (continuous joints included: see the module docstring).
        joint_limits: Per-joint overrides of the URDF limits.
        default_max_acceleration: Acceleration limit [rad/s²] of joints without an override.
        held_positions: Where joints that are not controlled are locked [rad or m]; absent ones at 0 clamped
            into their limits.

    Raises:
        KinematicsError: Unparsable URDF, unknown frame or joint, a joint that is not a 1-DoF joint, a
            joint both controlled and held, or a joint without a velocity limit (continuous joints often
            lack one: set it in the YAML).

    Attributes:
        continuous: Per joint (model order), True for a continuous joint. Its `lower` / `upper` are
            -inf / +inf unless overridden.
    """

    def __init__(
        self,
        urdf_xml: str,
        tip_frame: str,
        joint_names: Sequence[str] = (),
        joint_limits: Mapping[str, JointLimitOverride] | None = None,
        default_max_acceleration: float = 3.0,
        held_positions: Mapping[str, float] | None = None,
    ) -> None:
        try:
            full = pin.buildModelFromXML(urdf_xml)
        except (RuntimeError, ValueError) as err:
            raise KinematicsError(f"robot_description: cannot parse the URDF: {err}") from err
        if not full.existFrame(tip_frame):
            raise KinematicsError(
                f"ee_frame_name {tip_frame!r} is not a frame of the URDF; frames: {_frame_names(full)}"
            )
        controlled = list(joint_names) or _chain_joints(full, tip_frame)
        for name in controlled:
            if not full.existJointName(name):
                raise KinematicsError(f"joint_names: {name!r} is not a joint of the URDF")
            joint = full.joints[full.getJointId(name)]
            if joint.nv != 1 or joint.nq not in (1, 2):
                raise KinematicsError(
                    f"joint_names: {name!r} is not a 1-DoF revolute, continuous or prismatic joint "
                    f"(nq={joint.nq}, nv={joint.nv})"
                )
        locked = [jid for jid in range(1, full.njoints) if full.names[jid] not in controlled]
        held = _held_configuration(full, controlled, held_positions or {})
        _rename_clashing(full, locked)
        model = pin.buildReducedModel(full, locked, held) if locked else full
        self.model = model
        self.data = model.createData()
        self._pose_data = model.createData()  # for measured_pose, so it never disturbs a cycle's data
        self._pose_q: object = None
        self._step_data = model.createData()  # for tip_displacement (called between cycles' uses of data)
        self._q_pin_step = pin.neutral(model)
        self.nv = model.nv
        # Kinematic order of the controlled joints: index i of every array in this class.
        self.joint_names: tuple[str, ...] = tuple(model.names[1:])
        self.tip_frame = tip_frame
        self.tip_id = frame_index(model, tip_frame)
        self._tip_support = set(model.supports[model.frames[self.tip_id].parentJoint])

        # (q index, v index) of the 1-value joints and of the (cos, sin) continuous ones, model order.
        joints = [model.joints[jid] for jid in range(1, model.njoints)]
        self.continuous: tuple[bool, ...] = tuple(joint.nq == 2 for joint in joints)
        #: Linear joints (a rail): positions in m, velocities in m/s.
        self.prismatic: tuple[bool, ...] = tuple(joint.shortname() in _PRISMATIC for joint in joints)
        self._plain = not any(self.continuous)  # q is the angle array itself
        self._single = [(j.idx_q, j.idx_v) for j in joints if j.nq == 1]
        self._unbounded = [(j.idx_q, j.idx_v) for j in joints if j.nq == 2]
        self._q_pin = pin.neutral(model)  # conversion buffers: one per caller kind, never shared
        self._q_pin_pose = pin.neutral(model)
        self._q_pin_query = pin.neutral(model)
        lower = np.array([
            -math.inf if j.nq == 2 else model.lowerPositionLimit[j.idx_q] for j in joints
        ])
        upper = np.array([
            math.inf if j.nq == 2 else model.upperPositionLimit[j.idx_q] for j in joints
        ])
        velocity = model.velocityLimit.copy()
        acceleration = np.full(self.nv, float(default_max_acceleration))
        overrides = dict(joint_limits or {})
        for name, override in overrides.items():
            if name not in self.joint_names:
                raise KinematicsError(f"joint_limits/{name}: not a controlled joint {list(self.joint_names)}")
            i = self.joint_names.index(name)
            if override.min_position is not None:
                lower[i] = override.min_position
            if override.max_position is not None:
                upper[i] = override.max_position
            if override.max_velocity is not None:
                velocity[i] = override.max_velocity
            if override.max_acceleration is not None:
                acceleration[i] = override.max_acceleration
        for i, name in enumerate(self.joint_names):
            if not velocity[i] > 0.0 or not np.isfinite(velocity[i]):
                raise KinematicsError(
                    f"joint {name!r} has no velocity limit in the URDF: set joint_limits/{name}/max_velocity"
                )
            if not lower[i] < upper[i]:
                raise KinematicsError(f"joint {name!r} has no position range ({lower[i]} >= {upper[i]})")
        self.lower = lower
        self.upper = upper
        self.max_velocity = velocity
        self.max_acceleration = acceleration

        J = self.jacobian(self.neutral())
        if not np.any(J):
            raise KinematicsError(
                f"ee_frame_name {tip_frame!r} is not moved by joints {list(self.joint_names)}"
            )

    # --- queries -------------------------------------------------------------------------------------

    def neutral(self) -> FloatArray:
        """Neutral (all zero) configuration of the controlled joints, one angle each, a fresh array."""
        return np.zeros(self.nv)

    def pin_q(self, q: Sequence[float] | FloatArray, out: FloatArray | None = None) -> FloatArray:
        """Pinocchio configuration for the joint values `q` (one per joint, model order).

        Args:
            q: Joint angles [rad] or positions [m]; continuous joints as any (unwrapped) angle.
            out: Buffer of length ``model.nq`` to fill; None = a buffer of this model, overwritten by the
                next call (fine for the immediate Pinocchio call it feeds).

        Returns:
            `q` itself (as an array) when no joint is continuous, else `out` with (cos, sin) per continuous
            joint.
        """
        if self._plain:
            return q if isinstance(q, np.ndarray) else np.asarray(q, dtype=float)
        buf = self._q_pin_query if out is None else out
        for iq, iv in self._single:
            buf[iq] = q[iv]
        for iq, iv in self._unbounded:
            angle = q[iv]
            buf[iq] = math.cos(angle)
            buf[iq + 1] = math.sin(angle)
        return buf

    def angles(self, q_pin: FloatArray) -> FloatArray:
        """Joint values (one per joint, angles in (-pi, pi] for continuous joints) of a Pinocchio `q_pin`."""
        values = np.empty(self.nv)
        for iq, iv in self._single:
            values[iv] = q_pin[iq]
        for iq, iv in self._unbounded:
            values[iv] = math.atan2(q_pin[iq + 1], q_pin[iq])
        return values

    def has_frame(self, name: str) -> bool:
        """True if `name` is a frame (link or joint) of the model."""
        return bool(name) and self.model.existFrame(name)

    def frame_id(self, name: str) -> int:
        """Pinocchio id of frame `name`.

        Raises:
            KinematicsError: Unknown frame.
        """
        if not self.has_frame(name):
            raise KinematicsError(f"{name!r} is not a frame of the robot model")
        return frame_index(self.model, name)

    def moves_with_tip_chain(self, frame_id: int) -> bool:
        """True if the frame's placement is refreshed by :meth:`jacobian` (root or on the tip's chain)."""
        return self.model.frames[frame_id].parentJoint in self._tip_support

    def jacobian(self, q: FloatArray) -> FloatArray:
        """Tip Jacobian (6 x nv, linear rows first, LOCAL_WORLD_ALIGNED) at `q`.

        Also refreshes the placements of the joints on the tip's chain and of the tip frame in `self.data`.
        """
        q_pin = self.pin_q(q, self._q_pin)
        J: FloatArray = pin.computeFrameJacobian(
            self.model, self.data, q_pin, self.tip_id, pin.LOCAL_WORLD_ALIGNED
        )
        return J

    def frame_rotation(self, frame_id: int, q: FloatArray | None = None) -> FloatArray:
        """Rotation of a frame in the root frame, after :meth:`jacobian` (or at `q` if given).

        Frames off the tip's chain need `q` (a full forward kinematics), unless fixed to the root.
        """
        if q is not None:
            pin.forwardKinematics(self.model, self.data, self.pin_q(q, self._q_pin))
        rotation: FloatArray = pin.updateFramePlacement(self.model, self.data, frame_id).rotation
        return rotation

    def frame_pose(self, q: FloatArray, frame: str, relative_to: str = "") -> pin.SE3:
        """Pose of `frame` in `relative_to` (the root frame if empty) at configuration `q`.

        Raises:
            KinematicsError: Unknown frame.
        """
        fid = self.frame_id(frame)
        pin.forwardKinematics(self.model, self.data, self.pin_q(q, self._q_pin))
        pose = pin.updateFramePlacement(self.model, self.data, fid).copy()
        if relative_to:
            base = pin.updateFramePlacement(self.model, self.data, self.frame_id(relative_to))
            pose = base.actInv(pose)
        return pose


    def tip_displacement(
        self, q_from: Sequence[float] | FloatArray, q_to: Sequence[float] | FloatArray, out: FloatArray
    ) -> FloatArray:
        """The tip's displacement from `q_from` to `q_to` (model order) into `out` (6): translation, then
        rotation vector, both in root axes: what a LOCAL_WORLD_ALIGNED tip twist held constant integrates to.
        Uses data of its own (the cycle's data keeps its placements)."""
        model, data, tip = self.model, self._step_data, self.tip_id
        pin.forwardKinematics(model, data, self.pin_q(np.asarray(q_from, dtype=float), self._q_pin_step))
        start = pin.updateFramePlacement(model, data, tip)
        p0, R0 = start.translation.copy(), start.rotation.copy()
        pin.forwardKinematics(model, data, self.pin_q(np.asarray(q_to, dtype=float), self._q_pin_step))
        end = pin.updateFramePlacement(model, data, tip)
        out[:3] = end.translation - p0
        out[3:] = pin.log3(end.rotation @ R0.T)
        return out

    def measured_pose(self, q: Sequence[float], frame_id: int, base_id: int) -> FloatArray:
        """4x4 pose of frame `frame_id` in frame `base_id` at `q` (model order).

        Forward kinematics runs once per `q` object: several frames asked at the same state share it.
        """
        data = self._pose_data
        if q is not self._pose_q:
            pin.forwardKinematics(self.model, data, self.pin_q(np.asarray(q, dtype=float), self._q_pin_pose))
            self._pose_q = q
        pose = pin.updateFramePlacement(self.model, data, frame_id)
        if base_id != 0:  # frame 0 is the root ("universe")
            pose = pin.updateFramePlacement(self.model, data, base_id).actInv(pose)
        homogeneous: FloatArray = pose.homogeneous
        return homogeneous


_PRISMATIC = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")


def frame_index(model: pin.Model, name: str) -> int:
    """Pinocchio id of the frame `name` (an existing one), the link's when a joint has the same name (the
    SO-100's `gripper` is both: Pinocchio refuses to choose)."""
    for kind in (pin.BODY, pin.OP_FRAME, pin.FIXED_JOINT, pin.JOINT, pin.SENSOR):
        if model.existFrame(name, kind):
            index: int = model.getFrameId(name, kind)  # pinocchio: untyped
            return index
    raise KinematicsError(f"{name!r} is not a frame of the robot model")


def _rename_clashing(model: pin.Model, joints: Sequence[int]) -> None:
    """Renames the given joints (and their frames) that share their name with a link: Pinocchio's reduction
    looks their frames up by name and refuses to choose (the SO-100's `gripper` joint and link). They are
    locked: nothing refers to them by name afterwards."""
    for jid in joints:
        name = model.names[jid]
        if not model.existFrame(name, pin.BODY):
            continue
        for fid, frame in enumerate(model.frames):
            if frame.name == name and frame.type == pin.JOINT:
                frame.name = f"{name}#joint"
                model.frames[fid] = frame
        model.names[jid] = f"{name}#joint"


def _chain_joints(model: pin.Model, tip_frame: str) -> list[str]:
    """Names of the joints from the root to `tip_frame` (checked for 1 DoF by the caller)."""
    parent = model.frames[frame_index(model, tip_frame)].parentJoint
    return [model.names[jid] for jid in model.supports[parent][1:]]


def _held_configuration(full: pin.Model, controlled: Sequence[str], held: Mapping[str, float]) -> FloatArray:
    """Pinocchio's q of the full model with every joint that is not controlled at its held position."""
    q = pin.neutral(full)
    for name, value in held.items():
        if not full.existJointName(name):
            raise KinematicsError(f"held_joints: {name!r} is not a joint of the URDF")
        if name in controlled:
            raise KinematicsError(f"held_joints: {name!r} is a controlled joint (joint_names)")
        if not math.isfinite(float(value)):
            raise KinematicsError(f"held_joints: {name} must be a finite number, got {value!r}")
    for jid in range(1, full.njoints):
        name, joint = full.names[jid], full.joints[jid]
        if name in controlled or joint.nv != 1:
            continue
        value = float(held.get(name, 0.0))
        if joint.nq == 2:  # continuous: (cos, sin)
            q[joint.idx_q : joint.idx_q + 2] = (math.cos(value), math.sin(value))
        else:
            lo, hi = full.lowerPositionLimit[joint.idx_q], full.upperPositionLimit[joint.idx_q]
            q[joint.idx_q] = min(max(value, lo), hi) if name not in held else value
    return np.asarray(q, dtype=float)


def _frame_names(model: pin.Model) -> list[str]:
    return [frame.name for frame in model.frames if frame.type == pin.FrameType.BODY]
