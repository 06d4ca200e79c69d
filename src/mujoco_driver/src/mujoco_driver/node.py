"""mujoco_driver node: the rospy adapter around :class:`~mujoco_driver.sim.Simulation` (see the README).

One loop in the main thread steps the simulation in real time (a fixed wall-clock grid, see
:mod:`mujoco_driver.pacing`) and publishes the state; subscriber and service callbacks run in rospy's
threads and only call into the simulation while holding ``_lock`` (``Simulation`` is not thread-safe).
Messages and arrays are allocated once; the loop fills them in place. With ``~profile`` the node speaks as a
real driver through an :class:`~mujoco_driver.ros_emulation.EmulatedDriver` it owns.
"""

from __future__ import annotations

import faulthandler
import logging
import math
import os
import signal
import sys
import threading
import time
from typing import Any

import numpy as np
import rospy
from compliant_common.diagnostics import Report
from compliant_common.ros_diagnostics import DiagnosticsPublisher
from compliant_common.ros_master import MasterWatch
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.ros_time import timer
from compliant_common.rospy_internals import drop_clock_subscription, header_stamp_ns, set_rostime
from compliant_common.runtime import tune_runtime
from compliant_control_msgs.srv import PushEEF, PushEEFResponse
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension
from std_srvs.srv import Trigger, TriggerResponse
from trajectory_msgs.msg import JointTrajectory

from mujoco_driver.commands import trajectory_points, velocity_vector
from mujoco_driver.config import ConfigError, SceneConfig
from mujoco_driver.fixtures import hole_pose
from mujoco_driver.health import driver_health
from mujoco_driver.latency import LatencyProbe
from mujoco_driver.lockstep import Lockstep
from mujoco_driver.pacing import Pacer, RtfMeter, TrailingPublication
from mujoco_driver.params import DriverParamError, DriverSettings, load_scene, urdf_root_link
from mujoco_driver.profiles import DriverProfile, ProfileError
from mujoco_driver.ros_emulation import EmulatedDriver, resolve_profile
from mujoco_driver.scene import SceneError, surface_truth
from mujoco_driver.sim import CommandError, Simulation

__all__ = ["MujocoDriverNode", "main"]

_WARN_PERIOD = 2.0  # [s] throttle of warnings about bad commands
_MAX_STAMP_AGE = 0.1  # [s] older trajectory stamps are taken as "now"
_MAX_STAMP_AHEAD = 1.0  # [s] stamps further in the future too
# [s] Behind the wall clock by more than this (and a period), the loop steps without publishing until it has
# caught up. At 500 Hz that is one period, as before; at 1 kHz a 1 ms lag is an ordinary late wake-up on a
# loaded 2-core machine, and skipping those states costs the stack's controllers a cycle each (and moves
# contact_control's measured wrench rate, so its filter design, between ~0.9 and 1 kHz).
_CATCH_UP_LAG = 0.002
_LOCKSTEP_SLICE = 0.005  # [s] a lockstep wait wakes this often to publish and to see a stop
VIEWER_CLOSE_WAIT = 3.0  # [s] the viewer's close may take (its render thread answers within a frame)


class MujocoDriverNode:
    """Topics, services, the viewer and the stepping loop around one :class:`Simulation`; what a real driver
    offers besides (controllers, tf, reflex...) is its :class:`EmulatedDriver`'s.

    Args:
        settings: The validated node parameters.
        urdf: The robot description.
        scene_cfg: The scene settings.
        profile: A real driver's interface to speak (None: this driver's own, see the README).

    Raises:
        ConfigError, SceneError: If the URDF and the scene do not make a simulation.
        ProfileError: If the profile names links the description lacks.
    """

    def __init__(self, settings: DriverSettings, urdf: str, scene_cfg: SceneConfig,
                 profile: DriverProfile | None = None) -> None:
        self._s = s = settings
        self._sim = sim = Simulation(urdf, scene_cfg)
        if scene_cfg.hole is not None and scene_cfg.obstacle is not None:  # ground truth, for plots and tests
            rospy.set_param("~hole_pose", list(hole_pose(scene_cfg.obstacle, scene_cfg.hole)))
        if scene_cfg.surface is not None and scene_cfg.obstacle is not None:
            rospy.set_param("~surface", surface_truth(scene_cfg.obstacle, scene_cfg.surface))
        for entry in sim.scene.geometry:  # meshes converted or replaced for MuJoCo: say so, per link
            if entry.changed:
                rospy.loginfo("mujoco_driver: collision geometry of %s", entry)
        self._lock = threading.Lock()
        self._base_frame = s.base_frame or urdf_root_link(urdf)
        self._tf = for_this_node()  # the robot's tf prefix on the frames it publishes (README, Namespaces)
        self._clock_offset = 0.0  # simulated time before the last ~reset, so /clock never runs backwards
        # Made before anything is advertised: it refuses a profile naming links the description lacks.
        self._driver = EmulatedDriver(sim, profile, self._lock, self._tf) if profile is not None else None
        # Steps per publication; fractional for a profile's rate (30 Hz on 2 ms steps), exact on average.
        self._publish_every = (profile.publish_steps(sim.dt) if profile is not None
                               else s.publish_every(sim.dt))
        # ~eef_pose every this many state publications (at a profile's rate, not the settings' period).
        self._pose_every = max(1, round(s.eef_pose_period / (self._publish_every * sim.dt)))
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
        self._sim_time = 0.0
        # The published wrench: the simulated sensor's, or the emulated driver's (both filled in place).
        self._wrench_out = self._w if self._driver is None else self._driver.wrench

        # Preallocated messages.
        self._joint_msg = JointState(name=list(sim.joint_names))
        self._wrench_msg = WrenchStamped()
        self._wrench_msg.header.frame_id = self._tf.add(s.ft_frame or scene_cfg.links.ft_sensor)
        self._pose_msg = PoseStamped()
        self._pose_msg.header.frame_id = self._tf.add(self._base_frame)
        self._clock_msg = Clock()
        self._rtf_msg = Float64()
        self._rtf: float | None = None
        self._latency_p50_p99: tuple[float, float] | None = None
        self._dropped = 0.0
        self._warned_now: dict[str, int] = {}
        self._stamp = rospy.Time()
        self._state_stamp = rospy.Time()  # the pending joint state's (the shared one moves with /clock)
        self._latency = LatencyProbe(horizon=s.command_timeout)
        self._lockstep = Lockstep(s.lockstep_lead) if s.lockstep_lead > 0.0 else None
        # Published states are remembered only to place an echo's stamp: with no echo topic, not at all.
        self._echoed = self._lockstep if s.lockstep_echo_topic else None
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
            return rospy.Publisher(name, cls, queue_size=queue, tcp_nodelay=True)

        self._joint_pub = publisher(s.joint_states_topic, JointState)
        self._wrench_pub = publisher(s.wrench_topic, WrenchStamped)
        self._pose_pub = publisher("~eef_pose", PoseStamped)
        self._rtf_pub = publisher("~rtf", Float64)
        self._latency_pub = publisher("~command_latency", Float64MultiArray)
        self._health = DiagnosticsPublisher(self._health_report, self._base_frame)
        # The push in progress for RViz (compliant_rviz): latched, sent when one starts and, from a 10 Hz
        # timer off the simulation loop, when it ends.
        self._push_pub = rospy.Publisher("~active_push", WrenchStamped, queue_size=1, latch=True)
        self._push_shown: tuple[float, ...] | None = None
        self._push_lock = threading.Lock()
        self._push_timer = timer(0.1, self._show_push)
        self._clock_pub = publisher("/clock", Clock) if s.publish_clock else None
        if self._clock_pub is not None:
            drop_clock_subscription()  # see _publish_clock
        if self._driver is None:
            self._subs = [
                rospy.Subscriber(s.trajectory_command_topic, JointTrajectory, self._on_trajectory,
                                 queue_size=1, tcp_nodelay=True),
                rospy.Subscriber(s.velocity_command_topic, Float64MultiArray, self._on_velocity,
                                 queue_size=1, tcp_nodelay=True),
            ]
        else:
            self._subs = self._driver.subscribe_commands(self._on_trajectory, self._on_velocity)
        self._subs.append(rospy.Subscriber("~push_wrench", WrenchStamped, self._on_push_wrench, queue_size=1,
                                           tcp_nodelay=True))
        if self._echoed is not None:
            # Raw bytes: only the header's stamp is read, whatever the type (no deserialisation).
            self._subs.append(rospy.Subscriber(s.lockstep_echo_topic, rospy.AnyMsg, self._on_echo,
                                               queue_size=1, tcp_nodelay=True))
        self._services = [
            rospy.Service("~push", PushEEF, self._on_push),
            rospy.Service("~reset", Trigger, self._on_reset),
        ]
        if self._driver is not None:
            self._driver.advertise(publisher)
        self._viewer = self._open_viewer() if s.viewer else None
        self._viewer_opened = self._viewer is not None
        self._warned: dict[str, int] = {}
        self._last_warning: dict[str, float] = {}
        self._stop_requested = False
        rospy.loginfo(
            "mujoco_driver: %d joints %s, dt %.4f s, real-time factor %s, publishing every %d step(s)%s",
            n, list(sim.joint_names), sim.dt, s.real_time_factor or "max", self._publish_every,
            ", /clock" if s.publish_clock else "",
        )

    @property
    def dt(self) -> float:
        """Simulation timestep [s]."""
        return self._sim.dt

    # ------------------------------------------------------------------ loop
    def stop(self) -> None:
        """Ask the loop to end after the current step (safe to call from a signal handler)."""
        self._stop_requested = True

    def run(self) -> None:
        """Step and publish until :meth:`stop` or a ROS shutdown."""
        s, sim = self._s, self._sim
        pacer = Pacer(sim.dt, s.real_time_factor, s.max_lag)
        catch_up_lag = max(pacer.period, _CATCH_UP_LAG)
        meter = RtfMeter(s.rtf_period)
        countdown: float = 0
        next_view = 0.0
        # joint_states trail the wrench by a fraction of the wall-clock publish period (0 when running as fast
        # as possible).
        state = TrailingPublication(s.joint_states_phase * pacer.period * self._publish_every)
        pacer.start(time.monotonic())
        self._read_state()
        lockstep, waiting_since, current = self._lockstep, math.nan, True  # current: this state went out
        while not (self._stop_requested or rospy.is_shutdown()):
            now = time.monotonic()
            if state.due(now):
                self._publish_state()
                continue
            if lockstep is not None:
                why = lockstep.hold(sim.time)
                if why:
                    if not current:  # skipped while catching up: the stack needs it to answer
                        current = True
                        self._publish_current()
                        continue
                    if math.isnan(waiting_since):
                        waiting_since = now
                    if now - waiting_since < s.lockstep_wait:
                        lockstep.wait(sim.time, state.sleep_time(now, _LOCKSTEP_SLICE))
                        continue
                    lockstep.give_up()
                    rospy.logwarn("mujoco_driver: lockstep: no %s for %.2f s (wall time): running on; "
                                  "command_timeout stops the arm", why, now - waiting_since)
                if not math.isnan(waiting_since):  # a pause is not a backlog: no catching up after it
                    waiting_since = math.nan
                    now = time.monotonic()
                    pacer.start(now)
            wait = pacer.wait_time(now)
            if wait > 0.0:
                time.sleep(state.sleep_time(now, wait))  # ahead of the wall clock: never while catching up
                continue
            countdown -= 1
            # Catching up after a stall: step without publishing the intermediate states (publishing costs
            # several times the physics), so the simulation is back on time sooner; the newest state goes out.
            catching_up = pacer.lag(time.monotonic()) > catch_up_lag
            publish = countdown <= 0 and not catching_up
            if state.due(now, state_changes=publish):
                self._publish_state()
            tripped = False
            with self._lock:
                self._watchdog()
                sim.step()
                if publish:
                    tripped = self._read_state()
                else:
                    self._sim_time = sim.time
            current = publish
            pacer.step_done()
            if tripped:  # only a publishing step reads the state
                self._on_reflex()
            if self._clock_pub is not None and not catching_up:
                self._publish_clock()
            if publish:
                countdown = max(countdown, -1.0) + self._publish_every  # no burst after a backlog
                self._publish_wrench()
                if not state.armed(time.monotonic()):
                    self._publish_state()
            now = time.monotonic()
            if meter.update(now, self._clock_offset + self._sim_time):
                self._report(meter.value, pacer.dropped)
            if self._viewer is not None and now >= next_view:
                next_view = now + s.viewer_period
                self._sync_viewer()
        if self._viewer is not None:
            # Closing waits for the viewer's render thread; bounded, as a GL thread that never answers would
            # hold the driver (and roslaunch's shutdown) until killed.
            closer = threading.Thread(target=self._viewer.close, name="viewer-close", daemon=True)
            closer.start()
            closer.join(VIEWER_CLOSE_WAIT)
            if closer.is_alive():
                rospy.logwarn("mujoco_driver: the viewer did not close within %g s; exiting without it",
                              VIEWER_CLOSE_WAIT)

    @property
    def had_viewer(self) -> bool:
        """Whether a viewer window was opened (its threads may outlive the loop)."""
        return self._viewer_opened

    def _publish_current(self) -> None:
        """The state now, when stepping skipped it: read, stamped on /clock, its wrench and joint states."""
        with self._lock:
            tripped = self._read_state()
        if tripped:
            self._on_reflex()
        if self._clock_pub is not None:
            self._publish_clock()
        self._publish_wrench()
        self._publish_state()

    def _on_reflex(self) -> None:
        """An emulated reflex stopped the arm: it refuses commands now, so there is nothing to wait for."""
        if self._driver is not None:
            self._driver.on_reflex()
        if self._lockstep is not None:
            self._lockstep.command(self._sim.time, moving=False)

    def _watchdog(self) -> None:
        """Velocity target to zero when velocity commands stopped coming (like a real velocity controller)."""
        if self._velocity_active and self._sim.time - self._last_velocity_command > self._s.command_timeout:
            self._velocity_active = False
            if self._sim.mode == "velocity":
                self._sim.set_velocity_targets(self._zero)
                rospy.loginfo_throttle(_WARN_PERIOD, "mujoco_driver: velocity commands stopped: stopping")

    def _read_state(self) -> bool:
        """Copy the state into the buffers (under the lock); True if an emulated reflex tripped."""
        sim = self._sim
        data = sim.data
        np.take(data.qpos, self._qpos_adr, out=self._q)
        np.take(data.qvel, self._dof_adr, out=self._qd)
        np.take(data.qfrc_actuator, self._dof_adr, out=self._tau)
        sim.wrench(out=self._w)
        self._xpos[:] = self._xpos_src
        self._xquat[:] = self._xquat_src
        self._sim_time = sim.time
        return self._driver.update(self._w) if self._driver is not None else False

    def _now(self) -> float:
        """The stamp clock [s]: simulated time with /clock, else the wall clock."""
        return self._clock_offset + self._sim_time if self._clock_pub is not None else time.time()

    def _set_stamp(self) -> None:
        """Fill the shared stamp (main loop only: published messages reference it)."""
        seconds = self._now()
        secs = int(seconds)
        self._stamp.secs, self._stamp.nsecs = secs, int((seconds - secs) * 1e9)

    def _publish_clock(self) -> None:
        self._set_stamp()
        self._clock_msg.clock = self._stamp
        assert self._clock_pub is not None  # called only with a /clock publisher
        self._clock_pub.publish(self._clock_msg)
        # This node's own rospy clock: set directly instead of through its /clock subscription (dropped in
        # __init__), which would deserialise every message this loop publishes. rospy keeps a copy.
        set_rostime(self._stamp)

    def _publish_wrench(self) -> None:
        """The wrench of the state just read: it starts the force-control chain, so it goes out first."""
        self._set_stamp()
        w, msg = self._wrench_out, self._wrench_msg
        msg.header.stamp = self._stamp
        f, t = msg.wrench.force, msg.wrench.torque
        f.x, f.y, f.z, t.x, t.y, t.z = w.tolist()
        self._state_stamp.secs, self._state_stamp.nsecs = self._stamp.secs, self._stamp.nsecs
        self._latency.wrench_sent(time.monotonic())
        if self._echoed is not None:
            self._echoed.published(self._stamp.secs * 1_000_000_000 + self._stamp.nsecs, self._sim_time)
        self._wrench_pub.publish(msg)

    def _publish_state(self) -> None:
        """Joint states (and every few times the EEF pose) of the state the last wrench came from."""
        joint = self._joint_msg
        joint.header.stamp = self._state_stamp
        # Lists serialise fastest in genpy (numpy scalars go through a slower path).
        joint.position, joint.velocity, joint.effort = self._q.tolist(), self._qd.tolist(), self._tau.tolist()
        self._joint_pub.publish(joint)
        if self._driver is not None:
            self._driver.publish_state(self._state_stamp)
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

    def _report(self, rtf: float, dropped: float) -> None:
        self._rtf, self._dropped = rtf, dropped  # for /diagnostics (plain attributes: atomic to read)
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
        target = self._s.real_time_factor
        rospy.logdebug("mujoco_driver: real-time factor %.3f", rtf)
        if target > 0.0 and rtf < 0.9 * target:
            rospy.logwarn_throttle(
                10.0, "mujoco_driver: real-time factor %.2f (asked %.2f); %.2f s of backlog dropped so far",
                rtf, target, dropped,
            )
        with self._lock:
            warnings = self._sim.warnings()
        if warnings != self._warned:
            rospy.logwarn("mujoco_driver: MuJoCo warnings since the last reset: %s", warnings)
            self._warned = warnings
        self._warned_now = warnings

    def _health_report(self) -> Report:
        """The driver's /diagnostics (its own thread; mujoco_driver.health)."""
        return driver_health(rospy.get_name(), self._rtf, self._s.real_time_factor, self._dropped,
                             self._warned_now, self._sim.time, self._sim.mode, self._latency_p50_p99)

    # ---------------------------------------------------------------- viewer
    def _open_viewer(self) -> Any:
        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            rospy.logwarn("mujoco_driver: ~viewer is true but there is no DISPLAY: running headless")
            return None
        try:
            import mujoco.viewer

            return mujoco.viewer.launch_passive(self._sim.model, self._sim.data)
        except Exception as exc:  # any GL/GLFW failure: go on headless
            rospy.logwarn("mujoco_driver: cannot open the viewer (%s): running headless", exc)
            return None

    def _sync_viewer(self) -> None:
        assert self._viewer is not None
        if not self._viewer.is_running():
            self._viewer = None  # the user closed the window; the simulation goes on
            return
        with self._lock:
            self._viewer.sync()

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
        if controller is None or self._driver is None:
            return False
        reason = self._driver.refusal(controller)
        if reason:
            self._reject(f"{controller} command", CommandError(reason))
            if self._lockstep is not None:  # not following the stack: nothing to wait for
                self._lockstep.command(self._sim.time, moving=False)
        return bool(reason)

    def _on_trajectory(self, msg: JointTrajectory, controller: str | None = None) -> None:
        self._latency.command_received(time.monotonic(), time.time())
        raw = [(p.positions, p.velocities, p.time_from_start.to_sec()) for p in msg.points]
        stamp = msg.header.stamp.to_sec()
        with self._lock:
            if self._refused(controller):
                return
            sim = self._sim
            try:
                points = trajectory_points(msg.joint_names, raw, sim.joint_indices, sim.position_targets)
                start = None
                if stamp > 0.0:
                    # As ros_control's trajectory controller: the trajectory starts at its stamp, so a sender
                    # that stamps its messages gets no jitter from the transport. A stamp further off than
                    # _MAX_STAMP_AGE back or _MAX_STAMP_AHEAD ahead (another clock?) starts now.
                    delay = stamp - self._now()
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
            if self._lockstep is not None:
                self._lockstep.command(sim.time, moving=False)

    def _on_velocity(self, msg: Float64MultiArray, controller: str | None = None) -> None:
        self._latency.command_received(time.monotonic(), time.time())
        with self._lock:
            if self._refused(controller):
                return
            sim = self._sim
            try:
                sim.set_arm_velocity_targets(velocity_vector(msg.data, sim.arm_joint_names))
            except CommandError as exc:
                self._reject("velocity command", exc)
                return
            self._last_velocity_command = sim.time
            self._velocity_active = True
            if self._lockstep is not None:
                self._lockstep.command(sim.time, moving=any(msg.data))

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
        wrench = self._sim.push_wrench
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
                self._sim.push((f.x, f.y, f.z), (t.x, t.y, t.z), duration=self._s.push_timeout)
            except CommandError as exc:
                self._reject("push_wrench", exc)
                return
        self._show_push()

    def _on_push(self, req: Any) -> PushEEFResponse:
        f, t = req.wrench.force, req.wrench.torque
        with self._lock:
            try:
                self._sim.push((f.x, f.y, f.z), (t.x, t.y, t.z), duration=req.duration)
            except CommandError as exc:
                rospy.logwarn("mujoco_driver: ~push refused: %s", exc)
                return PushEEFResponse(success=False, message=str(exc))
        self._show_push()
        message = (f"pushing force [{f.x:g}, {f.y:g}, {f.z:g}] N, torque [{t.x:g}, {t.y:g}, {t.z:g}] Nm "
                   f"({self._base_frame}) for {req.duration:g} s")
        return PushEEFResponse(success=True, message=message)

    def _on_reset(self, _req: Any) -> TriggerResponse:
        with self._lock:
            self._clock_offset += self._sim.time
            self._sim.reset()
            if self._driver is not None:
                self._driver.reset()
            self._velocity_active = False
            if self._lockstep is not None:
                self._lockstep.reset()
            self._read_state()
        return TriggerResponse(success=True, message="back at the start pose, holding position")


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mujoco_driver`` executable."""
    # rospy's own SIGINT/SIGTERM handler closes every connection inside the signal handler, i.e. in the main
    # thread, which deadlocks when the signal lands while this thread is inside publish() holding a
    # connection's lock (one shutdown in ~10 at 1500 messages/s left the node hanging). Our handler only
    # asks the loop to stop; ROS is shut down afterwards, outside any publish().
    rospy.init_node("mujoco_driver", argv=argv if argv is not None else sys.argv, disable_signals=True)
    node: MujocoDriverNode | None = None
    stop_early = []

    def on_signal(_signum: int, _frame: Any) -> None:
        if node is not None:
            node.stop()
        else:
            stop_early.append(True)

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    try:
        params = rospy.get_param("~", {})
        use_sim_time = bool(rospy.get_param("/use_sim_time", False))
        settings = DriverSettings.from_params(params, use_sim_time=use_sim_time)  # unknown keys refused
        # ~robot_description (the simulated robot itself, as an emulated driver has it) wins over the shared
        # robot_description, which the user's own launch file may load, as on a real cell.
        key = "~robot_description" if rospy.has_param("~robot_description") else "robot_description"
        if not rospy.has_param(key):
            raise DriverParamError(f"{rospy.resolve_name('robot_description')} is not set (the URDF)")
        urdf = rospy.get_param(key)
        settings, profile = resolve_profile(settings)  # with ~profile, the real driver's topic names
        node = MujocoDriverNode(settings, urdf, load_scene(settings), profile)
    except (DriverParamError, ConfigError, SceneError, ProfileError) as exc:
        rospy.logfatal("mujoco_driver: %s", exc)
        rospy.signal_shutdown("bad configuration")
        return 1
    if settings.publish_clock and not rospy.get_param("/use_sim_time", False):
        rospy.logwarn("mujoco_driver: publishing /clock but /use_sim_time is false: other nodes use the wall "
                      "clock and see stamps in simulated time")
    # A new master (roscore restarted) gets this node's topics, services and parameters again.
    MasterWatch(
        lambda reason: rospy.logerr("mujoco_driver: %s; the arm stops when commands stop (command_timeout)",
                                    reason),
        lambda: None,
        params=["~", "robot_description", "/use_sim_time"],
    )
    faulthandler.register(signal.SIGUSR1, all_threads=True)  # `kill -USR1 <pid>`: every thread's stack
    tune_runtime(node.dt, switch_fraction=0.25)
    if not stop_early:
        node.run()
    rospy.signal_shutdown("stopped")
    if node.had_viewer:
        # The viewer's daemon threads sit in GLFW/OpenGL: the interpreter's exit could wait on them (a
        # roslaunch shutdown once hung until killed). The state is published and the logs are flushed.
        logging.shutdown()
        os._exit(0)
    return 0
