"""What a real driver publishes as its wrench, computed from the simulated wrist sensor (pure, numpy only).

The simulation's sensor reads the wrench the environment exerts on the tool (gravity, contacts, pushes,
the tool's inertial force) in the sensor frame. A driver reports something else:

* ``sensor``: that reading, only moved into the driver's frame;
* ``payload_compensated``: minus the weight of the payload set on the robot, as a controller that knows
  its payload (set right, its TCP wrench reads zero at rest in any orientation; set wrong,
  ``payload_mass_error`` and ``payload_com_error``, the difference's weight remains, turning with the tool);
* ``external_estimate``: a model-based estimate from joint torques (a torque-sensing arm's driver): net of
  the configured load's weight; an error of its joint-torque model (``torque_error``, smooth in the
  configuration: friction, an averaged dynamic model) shows through the pseudo-inverse of the transposed
  Jacobian;
* ``current_estimate``: an estimate from joint motor currents (an arm without a wrist sensor, a UR CB3):
  net of the payload, and low-pass filtered by the controller (``lag``); like the above, a torque model
  error may be set.

Then the profile's sign: -1 reports the wrench the robot exerts on the environment (the profile YAML says
which driver does that); the payload and torque model errors are part of the estimate and take it too.
Then the errors of a real sensor, each off unless the profile sets it (mujoco_driver's README, *Sensor
errors*): white noise per axis, a slow drift (AR(1): stationary std ``drift_*``, time constant
``drift_time_constant``), an offset that varies smoothly with the joint configuration (``offset_*``), and a
shift of the zero after a heavy contact (``contact_shift_*``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from mujoco_driver.profiles import WrenchSpec

__all__ = ["PeriodMean", "RateDivider", "Reflex", "WrenchModel", "change_frame", "gravity_wrench",
           "set_payload_weight", "wrench_from_joint_torques"]

GRAVITY = np.array([0.0, 0.0, -9.81])
# Damping of the least-squares inverse: none while the Jacobian's smallest singular value (mixed units: m
# for the linear rows) is over SINGULAR_BAND, growing to DAMPING at a singularity: the gain stays under
# 13 N per Nm. A torque-sensing arm's driver zeroes its estimate below 0.08 (the mujoco_driver README's
# Sensor errors); the robots' start poses are at 0.21.
SINGULAR_BAND = 0.08
DAMPING = 0.05


def gravity_wrench(mass: float, com: np.ndarray, origin: np.ndarray, rotation: np.ndarray,
                   gravity: np.ndarray = GRAVITY) -> np.ndarray:
    """Gravity's wrench on a body of ``mass`` with centre of mass ``com``, about ``origin``, in the frame
    ``rotation`` (columns: its axes in the world). Positions in the world [m]; returns [N, Nm]."""
    force = mass * gravity
    torque = np.cross(com - origin, force)
    return np.concatenate([rotation.T @ force, rotation.T @ torque])


def set_payload_weight(spec: WrenchSpec, mass: float, com: np.ndarray, origin: np.ndarray,
                       rotation: np.ndarray, gravity: np.ndarray = GRAVITY) -> np.ndarray:
    """The weight of the payload set on the robot, which a compensating driver removes: the true tool's
    ``mass`` and ``com`` (world) plus the spec's ``payload_mass_error`` and ``payload_com_error`` (the
    latter in the frame ``rotation``); otherwise as :func:`gravity_wrench`."""
    com_set = com + rotation @ np.asarray(spec.payload_com_error, dtype=float)
    return gravity_wrench(mass + spec.payload_mass_error, com_set, origin, rotation, gravity)


def wrench_from_joint_torques(jacobian: np.ndarray, torques: np.ndarray) -> np.ndarray:
    """The wrench ``w`` that best explains joint torques ``torques = J^T w``: least squares (a 7-joint arm
    has more torques than a wrench has components), damped near singularities (``SINGULAR_BAND``,
    ``DAMPING``), as an estimator of the external wrench from joint torques does.

    Args:
        jacobian: 6 x n, the frame's (linear rows about its origin), in its axes.
        torques: n joint torques [Nm].
    """
    u, s, vt = np.linalg.svd(jacobian, full_matrices=False)  # J = U S V^T: (J^T)^+ = U S^+ V^T
    smallest = s[-1]
    damping = DAMPING**2 * (1.0 - (smallest / SINGULAR_BAND) ** 2) if smallest < SINGULAR_BAND else 0.0
    return np.asarray(u @ (s / (s * s + damping) * (vt @ torques)))


def change_frame(wrench: np.ndarray, r_from: np.ndarray, p_from: np.ndarray, r_to: np.ndarray,
                 p_to: np.ndarray) -> np.ndarray:
    """The same wrench expressed in another frame, torque about that frame's origin.

    Args:
        wrench: [f, t] in frame "from", torque about its origin.
        r_from, p_from: Rotation (3x3) and origin of "from" in the world.
        r_to, p_to: Same for "to".
    """
    force_w = r_from @ wrench[:3]
    torque_w = r_from @ wrench[3:] + np.cross(p_from - p_to, force_w)
    return np.concatenate([r_to.T @ force_w, r_to.T @ torque_w])


class PeriodMean:
    """The mean of the wrenches of the steps between two publications (a profile's `period_mean`): `add`
    each step that publishes nothing, then `take` at the publishing step."""

    def __init__(self) -> None:
        self._sum = np.zeros(6)
        self._count = 0

    def add(self, wrench: np.ndarray) -> None:
        self._sum += wrench
        self._count += 1

    def take(self, wrench: np.ndarray) -> None:
        """Replaces the publishing step's `wrench` (in place) by the mean of it and those added since."""
        if self._count:
            wrench += self._sum
            wrench /= self._count + 1
            self._sum[:] = 0.0
            self._count = 0


class WrenchModel:
    """The driver's wrench from the simulated sensor's (see the module docstring).

    Args:
        spec: The profile's wrench section.
        n_joints: Number of joints (the offset and the torque error are functions of them).
        period: Time between two calls [s] (the drift and the lag advance by it).
    """

    def __init__(self, spec: WrenchSpec, n_joints: int, period: float = 0.002) -> None:
        if not period > 0.0:
            raise ValueError(f"period must be > 0, got {period}")
        self.spec = spec
        self._rng = np.random.default_rng(spec.seed)
        # Offset: each component a sine of a random direction in joint space (|direction| = offset_scale
        # rad^-1) with a random phase: smooth, bounded by the amplitude, different per configuration.
        directions = self._rng.normal(size=(6, n_joints))
        directions *= spec.offset_scale / np.linalg.norm(directions, axis=1, keepdims=True)
        self._directions = directions
        self._phases = self._rng.uniform(0.0, 2.0 * np.pi, 6)
        self._amplitude = np.array([spec.offset_force] * 3 + [spec.offset_torque] * 3)
        self._has_offset = bool(np.any(self._amplitude))
        # Joint-torque model error: a sine per joint shaped like the offset, from its own random stream so
        # that the streams above keep their numbers for a given seed.
        torque_rng = np.random.default_rng(np.random.SeedSequence(spec.seed, spawn_key=(1,)))
        directions = torque_rng.normal(size=(n_joints, n_joints))
        directions *= spec.offset_scale / np.linalg.norm(directions, axis=1, keepdims=True)
        self._torque_directions = directions
        self._torque_phases = torque_rng.uniform(0.0, 2.0 * np.pi, n_joints)
        self._noise = np.concatenate([_triple(spec.noise_force), _triple(spec.noise_torque)])
        # AR(1) drift x' = a x + sqrt(1 - a^2) sigma w: stationary std sigma, correlation time tau.
        self._drift_std = np.concatenate([_triple(spec.drift_force), _triple(spec.drift_torque)])
        self._has_drift = bool(np.any(self._drift_std)) and spec.drift_time_constant > 0.0
        a = np.exp(-period / spec.drift_time_constant) if self._has_drift else 0.0
        self._drift_a, self._drift_b = a, np.sqrt(1.0 - a * a) * self._drift_std
        self._drift = self._rng.normal(size=6) * self._drift_std if self._has_drift else np.zeros(6)
        self._lag = 1.0 - np.exp(-period / spec.lag) if spec.lag > 0.0 else 1.0
        self._lagged: np.ndarray | None = None
        self._shift = np.zeros(6)  # the zero's shift after heavy contacts
        self._peak = 0.0  # the contact's peak force while above contact_shift_threshold [N]
        self._bias = np.zeros(6)
        self._value = np.zeros(6)

    @property
    def shift(self) -> np.ndarray:
        """The zero's total shift from heavy contacts so far [N, Nm] (a copy)."""
        return self._shift.copy()

    @property
    def drift(self) -> np.ndarray:
        """The drift term's current value [N, Nm] (a copy)."""
        return self._drift.copy()

    def offset(self, q: np.ndarray) -> np.ndarray:
        """The configuration-dependent offset at joint positions ``q`` [N, Nm]."""
        if not self._has_offset:
            return np.zeros(6)
        return self._amplitude * np.sin(self._directions @ q + self._phases)

    def torque_error(self, q: np.ndarray) -> np.ndarray:
        """The joint-torque model error at joint positions ``q`` [Nm]."""
        if not self.spec.torque_error:
            return np.zeros(len(self._torque_phases))
        return self.spec.torque_error * np.sin(self._torque_directions @ q + self._torque_phases)

    def _contact(self, force: np.ndarray) -> None:
        """A heavy contact (over the threshold) leaves the zero shifted once it is released, by a fraction of
        its peak in a random direction (a recorded wrist sensor: ~9 N after a 116 N press)."""
        threshold = self.spec.contact_shift_threshold
        magnitude = float(np.linalg.norm(force))
        if magnitude > threshold:
            self._peak = max(self._peak, magnitude)
        elif self._peak > 0.0 and magnitude < 0.5 * threshold:
            direction = self._rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            self._shift[:3] += self.spec.contact_shift_fraction * self._peak * direction
            self._peak = 0.0

    def __call__(self, sensor: np.ndarray, weight: np.ndarray, q: np.ndarray,
                 jacobian: np.ndarray | None = None, payload: np.ndarray | None = None) -> np.ndarray:
        """The published wrench.

        Args:
            sensor: The simulated sensor's reading, already in the driver's frame [N, Nm].
            weight: The tool's weight in the same frame (:func:`gravity_wrench`) [N, Nm].
            q: Joint positions [rad].
            jacobian: The frame's Jacobian at ``q`` (see :func:`wrench_from_joint_torques`); needed only
                with ``torque_error``.
            payload: The weight of the payload set on the robot (:func:`set_payload_weight`), which the
                model removes instead of ``weight``; None: set right.

        Returns:
            The wrench the driver publishes (after :meth:`zero`'s bias).
        """
        value = self._value
        value[:] = sensor
        if self.spec.model != "sensor":
            value -= weight if payload is None else payload
        if self.spec.contact_shift_threshold > 0.0:
            self._contact(sensor[:3] - weight[:3])
        if self.spec.torque_error:
            # tau_err is read as joint torques of a wrench on the tool (tau = J^T w): part of the estimate
            # of the wrench on the robot, so it takes the sign below with the rest of it.
            if jacobian is None:
                raise ValueError("torque_error needs the wrench frame's Jacobian")
            value += wrench_from_joint_torques(jacobian, self.torque_error(q))
        value *= self.spec.sign
        if self._lag < 1.0:  # the controller's filter on a current-based estimate
            if self._lagged is None:
                self._lagged = value.copy()
            self._lagged += self._lag * (value - self._lagged)
            value[:] = self._lagged
        # Errors of the published value, whatever its sign.
        if self._has_offset:
            value += self.offset(q)
        if self._has_drift:
            self._drift *= self._drift_a
            self._drift += self._drift_b * self._rng.normal(size=6)
            value += self._drift
        if self._noise.any():
            value += self._rng.normal(0.0, 1.0, 6) * self._noise
        value += self._shift
        return value - self._bias

    def zero(self, published: np.ndarray) -> None:
        """Zero the sensor: what is published now reads zero from now on (``zero_ftsensor``)."""
        self._bias = self._bias + np.asarray(published, dtype=float)


def _triple(value: float | Sequence[float]) -> np.ndarray:
    """One number for three axes, or one each."""
    if isinstance(value, int | float):
        return np.full(3, float(value))
    return np.asarray(value, dtype=float).reshape(3)


class RateDivider:
    """Publish at ``rate`` on a simulation stepping every ``dt``: :meth:`due` once per step says whether
    this step publishes; the average rate is exact (30 Hz on 2 ms steps: every 16 or 17 steps)."""

    def __init__(self, dt: float, rate: float) -> None:
        if not (dt > 0.0 and rate > 0.0):
            raise ValueError(f"dt and rate must be > 0, got {dt}, {rate}")
        self.steps = max(1.0, 1.0 / (rate * dt))
        self._countdown = 0.0

    def due(self) -> bool:
        """Count one step; True when it publishes."""
        self._countdown -= 1.0
        if self._countdown > 0.0:
            return False
        # A backlog (the caller skipped publishing) does not turn into a burst.
        self._countdown = max(self._countdown, -1.0) + self.steps
        return True


class Reflex:
    """A collision reflex on the published wrench: trips when any component's magnitude exceeds its
    threshold; stays tripped (the arm takes no motion) until :meth:`recover`.

    Args:
        thresholds: [fx, fy, fz, tx, ty, tz] [N, Nm].
    """

    def __init__(self, thresholds: Sequence[float]) -> None:
        self.thresholds = np.asarray(thresholds, dtype=float)
        if self.thresholds.shape != (6,) or not np.all(self.thresholds > 0.0):
            raise ValueError(f"reflex thresholds: expected 6 positive numbers, got {list(thresholds)}")
        self.reason = ""

    @property
    def tripped(self) -> bool:
        """Whether the arm is stopped by the reflex."""
        return bool(self.reason)

    def check(self, wrench: np.ndarray) -> bool:
        """Look at one published wrench; True exactly when this one trips the reflex."""
        if self.reason:
            return False
        over = np.abs(wrench) > self.thresholds
        if not np.any(over):
            return False
        axes = ("fx", "fy", "fz", "tx", "ty", "tz")
        self.reason = "cartesian_reflex: " + ", ".join(
            f"|{axes[i]}| {abs(wrench[i]):.1f} > {self.thresholds[i]:g}" for i in np.flatnonzero(over))
        return True

    def recover(self) -> bool:
        """Clear the reflex; True if it was tripped."""
        was, self.reason = self.tripped, ""
        return was
