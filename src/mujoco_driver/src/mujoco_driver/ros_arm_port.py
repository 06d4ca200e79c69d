"""One simulated arm's ROS side: its topics, services, buffers and command handling (README).

The driver node (mujoco_driver.node) owns one `ArmPort` per arm it serves, one alone or several in a cell,
and calls them from its stepping loop; subscriber and service callbacks run in rospy's threads and call into
the simulation only under the node's lock (a MuJoCo world is not thread-safe). Messages and arrays are
allocated once and filled in place.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import rospy
from compliant_common.diagnostics import Report
from compliant_common.ros_diagnostics import DiagnosticsPublisher
from compliant_common.ros_time import timer
from compliant_common.rospy_internals import header_stamp_ns
from compliant_common.tf_prefix import TfPrefix
from compliant_control_msgs.srv import PushEEF, PushEEFResponse
from geometry_msgs.msg import PoseStamped, WrenchStamped
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension
from std_srvs.srv import Trigger, TriggerResponse
from trajectory_msgs.msg import JointTrajectory

from mujoco_driver.commands import trajectory_points, velocity_vector
from mujoco_driver.config import SceneConfig
from mujoco_driver.fixtures import hole_pose
from mujoco_driver.health import driver_health
from mujoco_driver.latency import LatencyProbe
from mujoco_driver.lockstep import Lockstep
from mujoco_driver.params import DriverSettings
from mujoco_driver.profiles import DriverProfile
from mujoco_driver.ros_emulation import EmulatedDriver
from mujoco_driver.scene import surface_truth
from mujoco_driver.sim import CommandError, Simulation
from mujoco_driver.wrench_models import PeriodMean

__all__ = ["ArmPort", "PortNames"]

_WARN_PERIOD = 2.0  # [s] throttle of warnings about bad commands
_MAX_STAMP_AGE = 0.1  # [s] older trajectory stamps are taken as "now"
_MAX_STAMP_AHEAD = 1.0  # [s] stamps further in the future too


@dataclass(frozen=True)
class PortNames:
    """Where an arm's names live: `node` is its driver's node name (its private names' namespace); `ns` the
    namespace of its relative names. Empty: rospy's own (the process's node and namespace)."""

    node: str = ""
    ns: str = ""

    def __call__(self, name: str) -> str:
        if not self.node or name.startswith("/"):
            return name
        if name.startswith("~"):
            return f"{self.node}/{name[1:]}"
        return f"{self.ns.rstrip('/')}/{name}"

    def node_name(self) -> str:
        return self.node or rospy.get_name()


class ArmPort:
    """One arm's topics, services, state buffers and command handling around its :class:`Simulation`.

    Args:
        settings: Its validated driver parameters.
        sim: Its simulation (alone, or an arm of a cell's world).
        scene_cfg: Its scene settings.
        base_frame: Its base frame (bare; `tf` adds the robot's prefix).
        lock: The node's simulation lock.
        clock: The node's stamp clock [s] (simulated time with /clock, else the wall clock).
        names: Where its names live.
        tf: Its robot's tf prefix.
        profile: A real driver's interface to speak (None: this driver's own).
        publish_clock: Whether the node publishes /clock (the lockstep's stamps are in simulated time).

    Raises:
        ProfileError: If the profile names links the description lacks.
    """

    def __init__(self, settings: DriverSettings, sim: Simulation, scene_cfg: SceneConfig, base_frame: str,
                 lock: threading.Lock, clock: Callable[[], float], names: PortNames, tf: TfPrefix,
                 profile: DriverProfile | None = None) -> None:
        self._s = s = settings
        self.sim = sim
        self._lock = lock
        self._clock = clock
        self._names = names
        self._tf = tf
        self._base_frame = base_frame
        if scene_cfg.hole is not None and scene_cfg.obstacle is not None:  # ground truth, for plots and tests
            rospy.set_param(names("~hole_pose"), list(hole_pose(scene_cfg.obstacle, scene_cfg.hole)))
        if scene_cfg.surface is not None and scene_cfg.obstacle is not None:
            rospy.set_param(names("~surface"), surface_truth(scene_cfg.obstacle, scene_cfg.surface))
        for entry in sim.scene.geometry:  # meshes converted or replaced for MuJoCo: say so, per link
            if entry.changed:
                rospy.loginfo("mujoco_driver: collision geometry of %s", entry)
        # Made before anything is advertised: it refuses a profile naming links the description lacks.
        self.driver = EmulatedDriver(sim, profile, lock, tf) if profile is not None else None
        # Steps per publication; fractional for a profile's rate (30 Hz on 2 ms steps), exact on average.
        self.publish_every = (profile.publish_steps(sim.dt) if profile is not None
                              else s.publish_every(sim.dt))
        # ~eef_pose every this many state publications (at a profile's rate, not the settings' period).
        self._pose_every = max(1, round(s.eef_pose_period / (self.publish_every * sim.dt)))
        self._pose_countdown = 1
        self._last_velocity_command = -math.inf  # [s of sim time]
        self._velocity_active = False
        self._zero = np.zeros(len(sim.joint_names))

        # State buffers, filled under the lock, published outside it.
        n, scene, data = len(sim.joint_names), sim.scene, sim.data
        self._q, self._qd, self._tau, self._w = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(6)
        self._xpos, self._xquat = np.zeros(3), np.zeros(4)
        self._qpos_adr, self._dof_adr = scene.qpos_adr, scene.dof_adr
        self._xpos_src, self._xquat_src = data.xpos[scene.eef_body], data.xquat[scene.eef_body]
        self.sim_time = 0.0
        # The published wrench: the simulated sensor's, or the emulated driver's (both filled in place).
        self._wrench_out = self._w if self.driver is None else self.driver.wrench
        # A profile's `period_mean`: the sensor's wrench over the steps between publications.
        self._mean = PeriodMean() if profile is not None and profile.wrench.period_mean else None

        self._joint_msg = JointState(name=list(sim.joint_names))
        self._wrench_msg = WrenchStamped()
        self._wrench_msg.header.frame_id = tf.add(s.ft_frame or scene_cfg.links.ft_sensor)
        self._pose_msg = PoseStamped()
        self._pose_msg.header.frame_id = tf.add(base_frame)
        self._rtf_msg = Float64()
        self.rtf: float | None = None
        self._latency_p50_p99: tuple[float, float] | None = None
        self.dropped = 0.0
        self._warned_now: dict[str, int] = {}
        self._warned: dict[str, int] = {}
        self._last_warning: dict[str, float] = {}
        self._stamp = rospy.Time()
        self._state_stamp = rospy.Time()  # the pending joint state's (the shared one moves with /clock)
        self._latency = LatencyProbe(horizon=s.command_timeout)
        self.lockstep = Lockstep(s.lockstep_lead) if s.lockstep_lead > 0.0 else None
        # Published states are remembered only to place an echo's stamp: with no echo topic, not at all.
        self._echoed = self.lockstep if s.lockstep_echo_topic else None
        self._latency_msg = Float64MultiArray()
        self._latency_msg.layout.dim = [MultiArrayDimension("command", 0, 0),
                                        MultiArrayDimension("received_wall_time_and_latency", 2, 2)]

        # rospy's Publisher does take tcp_nodelay (TCP_NODELAY on the publisher's socket; subscribers may ask
        # for it too). With a queue_size, publish() hands the bytes to a writer thread per subscriber, so a
        # stalled subscriber cannot block the loop; synchronous publishing writes the socket in this thread,
        # which costs about 40 % less CPU, but a subscriber that stops reading (`rostopic echo | less`)
        # would freeze the simulation once its socket buffer is full.
        queue = None if s.publish_synchronously else 10

        def publisher(name: str, cls: type) -> rospy.Publisher:
            return rospy.Publisher(names(name), cls, queue_size=queue, tcp_nodelay=True)

        self._joint_pub = publisher(s.joint_states_topic, JointState)
        self._wrench_pub = publisher(s.wrench_topic, WrenchStamped)
        self._pose_pub = publisher("~eef_pose", PoseStamped)
        self._rtf_pub = publisher("~rtf", Float64)
        self._latency_pub = publisher("~command_latency", Float64MultiArray)
        self._health = DiagnosticsPublisher(self._health_report, tf.add(base_frame))
        # The push in progress for RViz (compliant_rviz): latched, sent when one starts and, from a 10 Hz
        # timer off the simulation loop, when it ends.
        self._push_pub = rospy.Publisher(names("~active_push"), WrenchStamped, queue_size=1, latch=True)
        self._push_shown: tuple[float, ...] | None = None
        self._push_lock = threading.Lock()
        self._push_timer = timer(0.1, self._show_push)
        fast = {"queue_size": 1, "tcp_nodelay": True}
        if self.driver is None:
            self._subs = [
                rospy.Subscriber(names(s.trajectory_command_topic), JointTrajectory, self._on_trajectory,
                                 **fast),
                rospy.Subscriber(names(s.velocity_command_topic), Float64MultiArray, self._on_velocity,
                                 **fast),
            ]
        else:
            self._subs = self.driver.subscribe_commands(self._on_trajectory, self._on_velocity)
        self._subs.append(rospy.Subscriber(names("~push_wrench"), WrenchStamped, self._on_push_wrench,
                                           **fast))
        if self._echoed is not None:
            # Raw bytes: only the header's stamp is read, whatever the type (no deserialisation).
            self._subs.append(rospy.Subscriber(names(s.lockstep_echo_topic), rospy.AnyMsg, self._on_echo,
                                               **fast))
        self._services = [
            rospy.Service(names("~push"), PushEEF, self._on_push),
            rospy.Service(names("~reset"), Trigger, self._on_reset),
        ]
        if self.driver is not None:
            self.driver.advertise(publisher)
        self.reset_hook: Callable[[ArmPort], None] = lambda port: port.sim.reset()

    # ------------------------------------------------------------- the loop's calls
    def watchdog(self) -> None:
        """Under the lock: the velocity target back to zero when velocity commands stopped coming (like a real
        velocity controller)."""
        if self._velocity_active and self.sim.time - self._last_velocity_command > self._s.command_timeout:
            self._velocity_active = False
            if self.sim.mode == "velocity":
                self.sim.set_velocity_targets(self._zero)
                rospy.loginfo_throttle(_WARN_PERIOD, "mujoco_driver: velocity commands stopped: stopping")

    def skip_state(self) -> None:
        """Under the lock, after a step that publishes nothing: its time, and its wrench toward the period's
        mean when the profile asks for it."""
        self.sim_time = self.sim.time
        if self._mean is not None:
            self._mean.add(self.sim.wrench(out=self._w))

    def read_state(self) -> bool:
        """Under the lock: the state into the buffers; True if an emulated reflex tripped."""
        sim = self.sim
        data = sim.data
        np.take(data.qpos, self._qpos_adr, out=self._q)
        np.take(data.qvel, self._dof_adr, out=self._qd)
        np.take(data.qfrc_actuator, self._dof_adr, out=self._tau)
        sim.wrench(out=self._w)
        if self._mean is not None:
            self._mean.take(self._w)
        sim.world_pose(self._xpos_src, self._xquat_src, self._xpos, self._xquat)
        self.sim_time = sim.time
        return self.driver.update(self._w) if self.driver is not None else False

    def on_reflex(self) -> None:
        """An emulated reflex stopped the arm: it refuses commands now, so there is nothing to wait for."""
        if self.driver is not None:
            self.driver.on_reflex()
        if self.lockstep is not None:
            self.lockstep.command(self.sim.time, moving=False)

    def _set_stamp(self) -> None:
        seconds = self._clock()
        secs = int(seconds)
        self._stamp.secs, self._stamp.nsecs = secs, int((seconds - secs) * 1e9)

    def publish_wrench(self) -> None:
        """The wrench of the state just read: it starts the force-control chain, so it goes out first."""
        self._set_stamp()
        w, msg = self._wrench_out, self._wrench_msg
        msg.header.stamp = self._stamp
        f, t = msg.wrench.force, msg.wrench.torque
        f.x, f.y, f.z, t.x, t.y, t.z = w.tolist()
        self._state_stamp.secs, self._state_stamp.nsecs = self._stamp.secs, self._stamp.nsecs
        self._latency.wrench_sent(time.monotonic())
        if self._echoed is not None:
            self._echoed.published(self._stamp.secs * 1_000_000_000 + self._stamp.nsecs, self.sim_time)
        self._wrench_pub.publish(msg)

    def publish_state(self) -> None:
        """Joint states (and every few times the EEF pose) of the state the last wrench came from."""
        joint = self._joint_msg
        joint.header.stamp = self._state_stamp
        # Lists serialise fastest in genpy (numpy scalars go through a slower path).
        joint.position, joint.velocity, joint.effort = self._q.tolist(), self._qd.tolist(), self._tau.tolist()
        self._joint_pub.publish(joint)
        if self.driver is not None:
            self.driver.publish_state(self._state_stamp)
        self._pose_countdown -= 1
        if self._pose_countdown > 0:
            return
        self._pose_countdown = self._pose_every
        pose = self._pose_msg
        pose.header.stamp = self._state_stamp
        p, o = pose.pose.position, pose.pose.orientation
        p.x, p.y, p.z = self._xpos.tolist()
        o.w, o.x, o.y, o.z = self._xquat.tolist()  # MuJoCo quaternions are (w, x, y, z)
        self._pose_pub.publish(pose)

    def report(self, rtf: float, dropped: float) -> None:
        """The real-time factor, the command latencies and MuJoCo's warnings (every `rtf_period`)."""
        self.rtf, self.dropped = rtf, dropped  # for /diagnostics (plain attributes: atomic to read)
        self._rtf_msg.data = rtf
        self._rtf_pub.publish(self._rtf_msg)
        latencies = self._latency.take()
        if latencies:  # wrench published -> joint command received: the stack's end to end, for /diagnostics
            ordered = sorted(latencies[1::2])
            self._latency_p50_p99 = (ordered[len(ordered) // 2], ordered[int(0.99 * (len(ordered) - 1))])
        if latencies and self._latency_pub.get_num_connections() > 0:
            msg = self._latency_msg
            msg.layout.dim[0].size, msg.layout.dim[0].stride = len(latencies) // 2, len(latencies)
            msg.data = latencies
            self._latency_pub.publish(msg)
        with self._lock:
            warnings = self.sim.warnings()
        if warnings != self._warned:
            rospy.logwarn("mujoco_driver: MuJoCo warnings since the last reset: %s", warnings)
            self._warned = warnings
        self._warned_now = warnings

    def _health_report(self) -> Report:
        """The arm's /diagnostics (its own thread; mujoco_driver.health)."""
        return driver_health(self._names.node_name(), self.rtf, self._s.real_time_factor, self.dropped,
                             self._warned_now, self.sim.time, self.sim.mode, self._latency_p50_p99)

    # -------------------------------------------------------------- commands
    def _reject(self, what: str, exc: Exception) -> None:
        """Warn about a refused command, at most every _WARN_PERIOD per kind (rospy's throttle is per call
        site, so one kind of bad command would hide another)."""
        now = time.monotonic()
        if now - self._last_warning.get(what, -math.inf) >= _WARN_PERIOD:
            self._last_warning[what] = now
            rospy.logwarn(f"mujoco_driver: {what} ignored: {exc}")

    def _refused(self, controller: str | None) -> bool:
        """Under the lock: an emulated driver ignores commands to a controller that is not running, and all
        of them after a reflex (warned, throttled)."""
        if controller is None or self.driver is None:
            return False
        reason = self.driver.refusal(controller)
        if reason:
            self._reject(f"{controller} command", CommandError(reason))
            if self.lockstep is not None:  # not following the stack: nothing to wait for
                self.lockstep.command(self.sim.time, moving=False)
        return bool(reason)

    def _on_trajectory(self, msg: JointTrajectory, controller: str | None = None) -> None:
        self._latency.command_received(time.monotonic(), time.time())
        raw = [(p.positions, p.velocities, p.time_from_start.to_sec()) for p in msg.points]
        stamp = msg.header.stamp.to_sec()
        with self._lock:
            if self._refused(controller):
                return
            sim = self.sim
            try:
                points = trajectory_points(msg.joint_names, raw, sim.joint_indices, sim.position_targets)
                start = None
                if stamp > 0.0:
                    # As ros_control's trajectory controller: the trajectory starts at its stamp, so a sender
                    # that stamps its messages gets no jitter from the transport. A stamp further off than
                    # _MAX_STAMP_AGE back or _MAX_STAMP_AHEAD ahead (another clock?) starts now.
                    delay = stamp - self._clock()
                    if -_MAX_STAMP_AGE <= delay <= _MAX_STAMP_AHEAD:
                        start = sim.time + delay
                    else:
                        when = f"{-delay:.3f} s ago" if delay < 0 else f"{delay:.3f} s ahead"
                        self._reject("trajectory stamp", CommandError(
                            f"stamped {when} (clocks differ?): started now instead"))
                sim.set_trajectory(points, start_time=start)
            except CommandError as exc:
                self._reject("trajectory", exc)
                return
            self._velocity_active = False
            if self.lockstep is not None:
                self.lockstep.command(sim.time, moving=False)

    def _on_velocity(self, msg: Float64MultiArray, controller: str | None = None) -> None:
        self._latency.command_received(time.monotonic(), time.time())
        with self._lock:
            if self._refused(controller):
                return
            sim = self.sim
            try:
                sim.set_arm_velocity_targets(velocity_vector(msg.data, sim.arm_joint_names))
            except CommandError as exc:
                self._reject("velocity command", exc)
                return
            self._last_velocity_command = sim.time
            self._velocity_active = True
            if self.lockstep is not None:
                self.lockstep.command(sim.time, moving=any(msg.data))

    def _on_echo(self, msg: rospy.AnyMsg) -> None:
        """The stack answered a state: the one its header stamp names."""
        assert self._echoed is not None  # subscribed only with an echo topic
        stamp = header_stamp_ns(msg)
        if stamp is None:
            self._reject("lockstep echo", CommandError("no std_msgs/Header first in the message"))
            return
        self._echoed.echo(stamp)

    def _check_push_frame(self, frame: str) -> None:
        if frame and self._tf.bare(frame) != self._base_frame:
            raise CommandError(f"push wrench frame must be {self._base_frame!r} (or empty), got {frame!r}")

    def _show_push(self, _event: object = None) -> None:
        """Publishes ~active_push when the push changed (started, replaced or ended)."""
        wrench = self.sim.push_wrench
        with self._push_lock:
            if wrench == self._push_shown:
                return
            self._push_shown = wrench
        msg = WrenchStamped()
        msg.header.stamp, msg.header.frame_id = rospy.Time.now(), self._tf.add(self._base_frame)
        f, t = msg.wrench.force, msg.wrench.torque
        f.x, f.y, f.z, t.x, t.y, t.z = wrench
        self._push_pub.publish(msg)

    def _on_push_wrench(self, msg: WrenchStamped) -> None:
        f, t = msg.wrench.force, msg.wrench.torque
        with self._lock:
            try:
                self._check_push_frame(msg.header.frame_id)
                self.sim.push((f.x, f.y, f.z), (t.x, t.y, t.z), duration=self._s.push_timeout)
            except CommandError as exc:
                self._reject("push_wrench", exc)
                return
        self._show_push()

    def _on_push(self, req: Any) -> PushEEFResponse:
        f, t = req.wrench.force, req.wrench.torque
        with self._lock:
            try:
                self.sim.push((f.x, f.y, f.z), (t.x, t.y, t.z), duration=req.duration)
            except CommandError as exc:
                rospy.logwarn("mujoco_driver: ~push refused: %s", exc)
                return PushEEFResponse(success=False, message=str(exc))
        self._show_push()
        message = (f"pushing force [{f.x:g}, {f.y:g}, {f.z:g}] N, torque [{t.x:g}, {t.y:g}, {t.z:g}] Nm "
                   f"({self._base_frame}) for {req.duration:g} s")
        return PushEEFResponse(success=True, message=message)

    def _on_reset(self, _req: Any) -> TriggerResponse:
        with self._lock:
            self.reset_hook(self)
            if self.driver is not None:
                self.driver.reset()
            self._velocity_active = False
            if self.lockstep is not None:
                self.lockstep.reset()
            self.read_state()
        return TriggerResponse(success=True, message="back at the start pose, holding position")
