"""mujoco_driver node: the rospy adapter around :class:`~mujoco_driver.sim.Simulation` (see the README).

One loop in the main thread steps the simulation in real time (a fixed wall-clock grid, see
:mod:`mujoco_driver.pacing`) and has each arm's port (:mod:`mujoco_driver.ros_arm_port`) publish its
state: one arm alone, or the arms of a cell's world (mujoco_driver.cell_node). Subscriber and service
callbacks run in rospy's threads and only call into the simulation while holding ``_lock`` (MuJoCo is
not thread-safe).
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
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import rospy
from compliant_common.ros_master import MasterWatch
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.rospy_internals import drop_clock_subscription, set_rostime
from compliant_common.runtime import tune_runtime
from compliant_common.tf_prefix import TfPrefix
from rosgraph_msgs.msg import Clock

from mujoco_driver.config import ConfigError, SceneConfig
from mujoco_driver.pacing import Pacer, RtfMeter, TrailingPublication
from mujoco_driver.params import DriverParamError, DriverSettings, load_scene, urdf_root_link
from mujoco_driver.profiles import DriverProfile, ProfileError
from mujoco_driver.ros_arm_port import ArmPort, PortNames
from mujoco_driver.ros_emulation import resolve_profile
from mujoco_driver.scene import SceneError
from mujoco_driver.sim import Simulation

__all__ = ["ArmSetup", "MujocoDriverNode", "main", "serve", "watch_master"]

# [s] Behind the wall clock by more than this (and a period), the loop steps without publishing until it has
# caught up. At 500 Hz that is one period, as before; at 1 kHz a 1 ms lag is an ordinary late wake-up on a
# loaded 2-core machine, and skipping those states costs the stack's controllers a cycle each (and moves
# contact_control's measured wrench rate, so its filter design, between ~0.9 and 1 kHz).
_CATCH_UP_LAG = 0.002
_LOCKSTEP_SLICE = 0.005  # [s] a lockstep wait wakes this often to publish and to see a stop
VIEWER_CLOSE_WAIT = 3.0  # [s] the viewer's close may take (its render thread answers within a frame)


class Stepper(Protocol):
    """What the loop steps: one arm's Simulation or a cell's World."""

    model: Any
    data: Any

    @property
    def dt(self) -> float: ...

    @property
    def time(self) -> float: ...

    def step(self, n: int = 1) -> None: ...


@dataclass(frozen=True)
class ArmSetup:
    """One arm the node serves: its settings, simulation, scene, base frame (bare), names, tf prefix and
    the real driver it speaks as (None: this driver's own)."""

    settings: DriverSettings
    sim: Simulation
    scene: SceneConfig
    base_frame: str
    names: PortNames
    tf: TfPrefix
    profile: DriverProfile | None = None


class MujocoDriverNode:
    """The stepping loop, /clock and the viewer around one world, and an :class:`ArmPort` per arm.

    Args:
        settings: The loop's parameters (real-time factor, lag, /clock, viewer, lockstep wait, phases).
        stepper: What is stepped: the arm's Simulation, or a cell's World.
        arms: The arms served.

    Raises:
        ProfileError: If a profile names links the description lacks.
    """

    def __init__(self, settings: DriverSettings, stepper: Stepper, arms: Sequence[ArmSetup]) -> None:
        self._s = s = settings
        self._stepper = stepper
        self._lock = threading.Lock()
        self._clock_offset = 0.0  # simulated time before the last ~reset, so /clock never runs backwards
        self._sim_time = 0.0
        self._stamp = rospy.Time()
        self._clock_msg = Clock()
        queue = None if s.publish_synchronously else 10
        self._clock_pub = (rospy.Publisher("/clock", Clock, queue_size=queue, tcp_nodelay=True)
                           if s.publish_clock else None)
        if self._clock_pub is not None:
            drop_clock_subscription()  # see _publish_clock
        self._ports = [ArmPort(a.settings, a.sim, a.scene, a.base_frame, self._lock, self._now, a.names, a.tf,
                               a.profile) for a in arms]
        for port in self._ports:
            port.reset_hook = self._reset_arm
        self._viewer = self._open_viewer() if s.viewer else None
        self._viewer_opened = self._viewer is not None
        self._stop_requested = False
        for arm, port in zip(arms, self._ports, strict=True):
            rospy.loginfo(
                "mujoco_driver: %s%d joints %s, dt %.4f s, real-time factor %s, publishing every %g "
                "step(s)%s",
                f"{arm.names.node}: " if arm.names.node else "", len(arm.sim.joint_names),
                list(arm.sim.joint_names), stepper.dt, s.real_time_factor or "max", port.publish_every,
                ", /clock" if s.publish_clock else "",
            )

    @classmethod
    def alone(cls, settings: DriverSettings, urdf: str, scene_cfg: SceneConfig,
              profile: DriverProfile | None = None) -> MujocoDriverNode:
        """The node of one arm, its names rospy's own.

        Raises:
            ConfigError, SceneError: If the URDF and the scene do not make a simulation.
            ProfileError: If the profile names links the description lacks.
        """
        sim = Simulation(urdf, scene_cfg)
        base = settings.base_frame or urdf_root_link(urdf)
        return cls(settings, sim, [ArmSetup(settings, sim, scene_cfg, base, PortNames(), for_this_node(),
                                            profile)])

    @property
    def dt(self) -> float:
        """Simulation timestep [s]."""
        return self._stepper.dt

    @property
    def ports(self) -> list[ArmPort]:
        """The arms' ports."""
        return self._ports

    # ------------------------------------------------------------------ loop
    def stop(self) -> None:
        """Ask the loop to end after the current step (safe to call from a signal handler)."""
        self._stop_requested = True

    def run(self) -> None:
        """Step and publish until :meth:`stop` or a ROS shutdown."""
        s, stepper, ports = self._s, self._stepper, self._ports
        # On simulated time a late step slows the simulation rather than skipping states (README, How it runs)
        pacer = Pacer(stepper.dt, s.real_time_factor, s.max_lag, catch_up=not s.publish_clock)
        catch_up_lag = max(pacer.period, _CATCH_UP_LAG)
        meter = RtfMeter(s.rtf_period)
        countdowns: list[float] = [0.0] * len(ports)
        next_view = 0.0
        # joint_states trail the wrench by a fraction of the wall-clock publish period (0 when running as fast
        # as possible).
        states = [TrailingPublication(s.joint_states_phase * pacer.period * port.publish_every)
                  for port in ports]
        pacer.start(time.monotonic())
        with self._lock:
            for port in ports:
                port.read_state()
        # The wait for a silent stack, in wall time the loop was awake for: a freeze of the whole machine
        # (every process descheduled at once) counts as two slices at most, not as the stack's silence.
        waited, waited_at, current = math.nan, math.nan, True  # current: this state went out
        while not (self._stop_requested or rospy.is_shutdown()):
            now = time.monotonic()
            due = [i for i, state in enumerate(states) if state.due(now)]
            if due:
                for i in due:
                    ports[i].publish_state()
                continue
            holding = next(((port, why) for port in ports if port.lockstep is not None
                            for why in (port.lockstep.hold(stepper.time),) if why), None)
            if holding is not None:
                port, why = holding
                if not current:  # skipped while catching up: the stack needs it to answer
                    current = True
                    self._publish_current()
                    continue
                if math.isnan(waited):
                    waited, waited_at = 0.0, now
                waited += min(now - waited_at, 2.0 * _LOCKSTEP_SLICE)
                waited_at = now
                if waited < s.lockstep_wait:
                    assert port.lockstep is not None
                    slice_ = min(st.sleep_time(now, _LOCKSTEP_SLICE) for st in states)
                    port.lockstep.wait(stepper.time, slice_)
                    continue
                for other in ports:
                    if other.lockstep is not None:
                        other.lockstep.give_up()
                rospy.logwarn("mujoco_driver: lockstep: no %s for %.2f s (wall time awake): running on; "
                              "command_timeout stops the arm", why, waited)
            if not math.isnan(waited):  # a pause is not a backlog: no catching up after it
                waited = math.nan
                now = time.monotonic()
                pacer.start(now)
            wait = pacer.wait_time(now)
            if wait > 0.0:
                # ahead of the wall clock: never while catching up
                time.sleep(min(state.sleep_time(now, wait) for state in states))
                continue
            # Catching up after a stall: step without publishing the intermediate states (publishing costs
            # several times the physics), so the simulation is back on time sooner; the newest state goes out.
            catching_up = pacer.lag(time.monotonic()) > catch_up_lag
            publish = [False] * len(ports)
            for i, state in enumerate(states):
                countdowns[i] -= 1
                publish[i] = countdowns[i] <= 0 and not catching_up
                if state.due(now, state_changes=publish[i]):
                    ports[i].publish_state()
            tripped = [False] * len(ports)
            with self._lock:
                for port in ports:
                    port.watchdog()
                stepper.step()
                self._sim_time = stepper.time
                for i, port in enumerate(ports):
                    if publish[i]:
                        tripped[i] = port.read_state()
                    else:
                        port.skip_state()
            current = all(publish)
            pacer.step_done()
            for i, port in enumerate(ports):
                if tripped[i]:  # only a publishing step reads the state
                    port.on_reflex()
            if self._clock_pub is not None and not catching_up:
                self._publish_clock()
            for i, port in enumerate(ports):
                if publish[i]:
                    countdowns[i] = max(countdowns[i], -1.0) + port.publish_every  # no burst after a backlog
                    port.publish_wrench()
                    if not states[i].armed(time.monotonic()):
                        port.publish_state()
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
            tripped = [port.read_state() for port in self._ports]
        for port, trip in zip(self._ports, tripped, strict=True):
            if trip:
                port.on_reflex()
        if self._clock_pub is not None:
            self._publish_clock()
        for port in self._ports:
            port.publish_wrench()
            port.publish_state()

    def _reset_arm(self, port: ArmPort) -> None:
        """Under the lock: an arm's ~reset. An arm alone starts its time again; /clock does not go back."""
        before = self._stepper.time
        port.sim.reset()
        self._clock_offset += before - self._stepper.time
        self._sim_time = self._stepper.time

    def _now(self) -> float:
        """The stamp clock [s]: simulated time with /clock, else the wall clock."""
        return self._clock_offset + self._sim_time if self._clock_pub is not None else time.time()

    def _publish_clock(self) -> None:
        seconds = self._now()
        secs = int(seconds)
        self._stamp.secs, self._stamp.nsecs = secs, int((seconds - secs) * 1e9)
        self._clock_msg.clock = self._stamp
        assert self._clock_pub is not None  # called only with a /clock publisher
        self._clock_pub.publish(self._clock_msg)
        # This node's own rospy clock: set directly instead of through its /clock subscription (dropped in
        # __init__), which would deserialise every message this loop publishes. rospy keeps a copy.
        set_rostime(self._stamp)

    def _report(self, rtf: float, dropped: float) -> None:
        target = self._s.real_time_factor
        rospy.logdebug("mujoco_driver: real-time factor %.3f", rtf)
        if target > 0.0 and rtf < 0.9 * target:
            rospy.logwarn_throttle(
                10.0, "mujoco_driver: real-time factor %.2f (asked %.2f); %.2f s of backlog dropped so far",
                rtf, target, dropped,
            )
        for port in self._ports:
            port.report(rtf, dropped)

    # ---------------------------------------------------------------- viewer
    def _open_viewer(self) -> Any:
        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            rospy.logwarn("mujoco_driver: ~viewer is true but there is no DISPLAY: running headless")
            return None
        try:
            refused = _display_refusal()
            if refused:  # MuJoCo's viewer would end the whole process on it
                rospy.logwarn("mujoco_driver: cannot open the viewer (%s): running headless", refused)
                return None
            import mujoco.viewer

            return mujoco.viewer.launch_passive(self._stepper.model, self._stepper.data)
        except Exception as exc:  # any other GL/GLFW failure: go on headless
            rospy.logwarn("mujoco_driver: cannot open the viewer (%s): running headless", exc)
            return None

    def _sync_viewer(self) -> None:
        assert self._viewer is not None
        if not self._viewer.is_running():
            self._viewer = None  # the user closed the window; the simulation goes on
            return
        with self._lock:
            self._viewer.sync()


def _display_refusal() -> str:
    """Why GLFW cannot open the display, '' if it can (MuJoCo's viewer exits the process when it cannot)."""
    import warnings

    import glfw

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if glfw.init():
            return ""
    return "; ".join(str(w.message) for w in caught) or "glfwInit failed"


def serve(name: str, build: Callable[[], MujocoDriverNode], argv: list[str] | None = None,
          started: Callable[[MujocoDriverNode], None] | None = None) -> int:
    """Runs a driver node named `name` made by `build` until SIGINT/SIGTERM or a ROS shutdown; 1 if `build`
    refuses its configuration (logged as fatal)."""
    # rospy's own SIGINT/SIGTERM handler closes every connection inside the signal handler, i.e. in the main
    # thread, which deadlocks when the signal lands while this thread is inside publish() holding a
    # connection's lock (one shutdown in ~10 at 1500 messages/s left the node hanging). Our handler only
    # asks the loop to stop; ROS is shut down afterwards, outside any publish().
    rospy.init_node(name, argv=argv if argv is not None else sys.argv, disable_signals=True)
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
        node = build()
    except (DriverParamError, ConfigError, SceneError, ProfileError) as exc:
        rospy.logfatal("%s: %s", name, exc)
        rospy.signal_shutdown("bad configuration")
        return 1
    if started is not None:
        started(node)
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


def _alone() -> MujocoDriverNode:
    """The node of the robot in `robot_description`, from the private parameters."""
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
    if settings.publish_clock and not rospy.get_param("/use_sim_time", False):
        rospy.logwarn("mujoco_driver: publishing /clock but /use_sim_time is false: other nodes use the wall "
                      "clock and see stamps in simulated time")
    return MujocoDriverNode.alone(settings, urdf, load_scene(settings), profile)


def watch_master(params: Sequence[str]) -> None:
    """A new master (roscore restarted) gets this node's topics, services and `params` again."""
    MasterWatch(
        lambda reason: rospy.logerr("mujoco_driver: %s; the arm stops when commands stop (command_timeout)",
                                    reason),
        lambda: None,
        params=params,
    )


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mujoco_driver`` executable."""
    return serve("mujoco_driver", _alone, argv,
                 lambda _node: watch_master(["~", "robot_description", "/use_sim_time"]))
