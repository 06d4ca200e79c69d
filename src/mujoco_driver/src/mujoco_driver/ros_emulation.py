"""The ROS side of driver emulation (see the README's *Driver emulation*), around the pure
:class:`~mujoco_driver.emulation.DriverEmulation`: the profile resolved from the node's parameters, and what
a real driver offers besides joint states, the wrench and command handling, which stay with the node.

The node owns one :class:`EmulatedDriver` when ``~profile`` is set and calls it from its loop (under its
simulation lock where a method says so); the services and the action take that lock themselves.
"""

from __future__ import annotations

import dataclasses
import functools
import threading
from collections.abc import Callable
from typing import Any

import numpy as np
import roslib.message
import rospy
from compliant_common.tf_prefix import TfPrefix
from geometry_msgs.msg import TransformStamped
from std_msgs.msg import Bool, Float64, Float64MultiArray
from std_srvs.srv import Trigger, TriggerResponse
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory

from mujoco_driver.emulation import DriverEmulation
from mujoco_driver.params import DriverSettings
from mujoco_driver.profiles import DriverProfile, ProfileError, load_profile, option_params
from mujoco_driver.sim import Simulation

__all__ = ["EmulatedDriver", "PublisherFactory", "resolve_profile"]

#: The node's way of making publishers (its queue size and TCP_NODELAY), used for the driver's too.
PublisherFactory = Callable[[str, type], rospy.Publisher]
#: A node command callback: (message, controller=<name>).
CommandCallback = Callable[..., None]


def resolve_profile(settings: DriverSettings) -> tuple[DriverSettings, DriverProfile | None]:
    """The profile ``~profile`` names (None: not emulating) and the settings with its real driver's names.

    Options the user's ``~profile_options`` leave unset are read from the parameters the real driver reads
    them from (the profile's ``option_params``), so a robot package's driver configuration reaches the
    emulation as it reaches the real driver.

    Raises:
        ProfileError: No such profile, or a bad option.
    """
    if not settings.profile:
        return settings, None
    options = dict(settings.profile_options or {})
    for option, name in option_params(settings.profile).items():
        if option not in options and rospy.has_param(name):  # the driver configuration's value
            options[option] = rospy.get_param(name)
            rospy.loginfo("mujoco_driver: option %s = %r from parameter %s", option, options[option],
                          rospy.resolve_name(name))
    profile = load_profile(settings.profile, options)
    # The real driver's names win over the driver's own topic parameters.
    settings = dataclasses.replace(settings, joint_states_topic=profile.joint_states_topic,
                                   wrench_topic=profile.wrench.topic, ft_frame=profile.wrench.frame)
    return settings, profile


class EmulatedDriver:
    """A real driver's controllers, tf, speed scaling, wrench zeroing and reflex on one simulation.

    Args:
        sim: The simulation (called only under ``lock``).
        profile: The resolved profile.
        lock: The node's simulation lock.
        prefix: The robot's tf prefix, on the frames of the tf it publishes.

    Raises:
        ProfileError: If the profile names links the description lacks (before anything is advertised).
    """

    def __init__(self, sim: Simulation, profile: DriverProfile, lock: threading.Lock,
                 prefix: TfPrefix | None = None) -> None:
        self.profile = profile
        self._emu = emu = DriverEmulation(sim, profile)
        self._lock = lock
        #: What the driver publishes as its wrench [N, Nm]; :attr:`update` fills it in place.
        self.wrench: np.ndarray = emu.wrench
        # The pure core's own methods, bound here so the loop pays no extra call per publication.
        #: Under the lock, at every publication: sensor wrench -> True when the reflex tripped.
        self.update: Callable[[np.ndarray], bool] = emu.update
        #: Under the lock: why a command to a controller does not move the arm now ("" = it does).
        self.refusal: Callable[[str], str] = emu.refusal
        self._tf_msg = TFMessage(transforms=[TransformStamped() for _ in profile.tf])
        prefix = prefix or TfPrefix()
        for t, spec in zip(self._tf_msg.transforms, profile.tf, strict=True):
            t.header.frame_id, t.child_frame_id = prefix.add(spec.parent), prefix.add(spec.child)
        self._scaling_msg = Float64(1.0)
        self._tf_pub: rospy.Publisher | None = None
        self._scaling_pub: rospy.Publisher | None = None
        self._state_pub: rospy.Publisher | None = None  # the reflex's robot state message, if any
        self._state_msg: Any = None
        self._recovery: Any = None  # actionlib.SimpleActionServer, with a reflex
        self._safety_pubs: tuple[rospy.Publisher, rospy.Publisher] | None = None  # with a protective stop
        self._services: list[rospy.Service] = []

    def subscribe_commands(self, on_trajectory: CommandCallback,
                           on_velocity: CommandCallback) -> list[rospy.Subscriber]:
        """One command topic per command controller, as ros_control: ``<controller>/command``; the node's
        callback gets ``controller=<name>`` to ask :attr:`refusal`."""
        kinds = {"trajectory": (JointTrajectory, on_trajectory), "velocity": (Float64MultiArray, on_velocity)}
        return [
            rospy.Subscriber(f"{c.name}/command", kinds[c.command][0],
                             functools.partial(kinds[c.command][1], controller=c.name),
                             queue_size=1, tcp_nodelay=True)
            for c in self.profile.controllers if c.command != "none"
        ]

    def advertise(self, publisher: PublisherFactory) -> None:
        """The real driver's other topics, services and action (the node calls it after its own)."""
        from controller_manager_msgs.srv import ListControllers, SwitchController

        profile = self.profile
        self._tf_pub = publisher("/tf", TFMessage)
        if profile.speed_scaling_topic:
            self._scaling_pub = publisher(profile.speed_scaling_topic, Float64)
        cm = profile.controller_manager
        self._services += [
            rospy.Service(f"{cm}/list_controllers", ListControllers, self._on_list_controllers),
            rospy.Service(f"{cm}/switch_controller", SwitchController, self._on_switch_controller),
        ]
        if profile.wrench.zero_service:
            self._services.append(rospy.Service(profile.wrench.zero_service, Trigger, self._on_zero))
        if profile.reflex is not None:
            import actionlib

            reflex = profile.reflex
            if reflex.state is not None:
                self._state_msg = _message_class(reflex.state.type)()
                self._state_pub = publisher(reflex.state.topic, type(self._state_msg))
            self._recovery = actionlib.SimpleActionServer(reflex.recovery_action,
                                                          _message_class(reflex.recovery_type),
                                                          self._on_recovery, auto_start=False)
            self._recovery.start()
        if profile.protective_stop is not None:
            self._advertise_protective_stop(profile.protective_stop)
        rospy.loginfo("mujoco_driver: speaking as %s (%s): %.0f Hz, wrench %s in %s (%s), running %s",
                      profile.driver, dict(profile.options), profile.publish_rate, profile.wrench.topic,
                      profile.wrench.frame, profile.wrench.model, self._emu.controllers.running())

    def _advertise_protective_stop(self, spec: Any) -> None:
        """ur_robot_driver's safety and robot mode, program state and the services that recover."""
        from ur_dashboard_msgs.msg import RobotMode, SafetyMode

        self._robot_mode_pub = rospy.Publisher(spec.robot_mode_topic, RobotMode, queue_size=1, latch=True)
        # A protective stop leaves the robot mode as it is (the safety mode changes).
        self._robot_mode_pub.publish(RobotMode(RobotMode.RUNNING))
        self._safety_pubs = (rospy.Publisher(spec.safety_mode_topic, SafetyMode, queue_size=1, latch=True),
                             rospy.Publisher(spec.program_running_topic, Bool, queue_size=1, latch=True))
        self._services.append(rospy.Service(spec.unlock_service, Trigger, self._on_unlock))
        self._services += [rospy.Service(name, Trigger, self._on_play) for name in spec.play_services]
        self._publish_safety()

    def _publish_safety(self) -> None:
        from ur_dashboard_msgs.msg import SafetyMode

        stop = self._emu.stop
        assert stop is not None and self._safety_pubs is not None
        self._safety_pubs[0].publish(SafetyMode(stop.safety_mode))
        self._safety_pubs[1].publish(Bool(stop.program_running))

    # ------------------------------------------------------------- from the loop
    def publish_state(self, stamp: rospy.Time) -> None:
        """tf and speed scaling with the joint state they belong to (same stamp)."""
        assert self._tf_pub is not None  # made by advertise
        for t, (pos, quat) in zip(self._tf_msg.transforms, self._emu.transforms, strict=True):
            t.header.stamp = stamp
            tr, rot = t.transform.translation, t.transform.rotation
            tr.x, tr.y, tr.z = pos.tolist()
            rot.x, rot.y, rot.z, rot.w = quat.tolist()
        if self._tf_msg.transforms:
            self._tf_pub.publish(self._tf_msg)
        if self._scaling_pub is not None:
            self._scaling_pub.publish(self._scaling_msg)
        if self._state_pub is not None:
            self._publish_robot_state(stamp)

    def _publish_robot_state(self, stamp: rospy.Time) -> None:
        """The reflex's robot state message (profile ``reflex.state``): the robot mode, the joints and the
        wrench as this state's, the flags of a reflex; the other fields keep their defaults."""
        msg, emu, spec = self._state_msg, self._emu, self.profile.reflex
        assert spec is not None and spec.state is not None and self._state_pub is not None
        state = spec.state
        held = emu.reflex is not None and emu.reflex.tripped
        msg.header.stamp = stamp
        n = len(getattr(msg, state.joints))  # a fixed-size array: the arm's joints, then zeros
        q, dq = np.zeros(n), np.zeros(n)
        m = min(n, len(emu.state_q))
        q[:m], dq[:m] = emu.state_q[:m], emu.state_dq[:m]
        setattr(msg, state.joints, q.tolist())
        setattr(msg, state.velocities, dq.tolist())
        setattr(msg, state.wrench, self.wrench.tolist())
        setattr(msg, state.mode_field, state.stopped if held else state.moving)
        for path in state.held_flags:
            _set_field(msg, path, held)
        for path in state.tripped_flags:
            if held:
                _set_field(msg, path, True)
        self._state_pub.publish(msg)

    def on_reflex(self) -> None:
        """The reflex or the protective stop tripped at the last :attr:`update` (outside the lock): say so."""
        reflex, spec, stop = self._emu.reflex, self.profile.reflex, self._emu.stop
        if stop is not None and stop.reason:
            assert self.profile.protective_stop is not None
            rospy.logerr("mujoco_driver: %s: the arm stopped; commands are ignored until %s and %s are "
                         "called", stop.reason, self.profile.protective_stop.unlock_service,
                         self.profile.protective_stop.play_services[0])
            self._publish_safety()
        if reflex is not None and reflex.tripped:  # the next robot state says so
            assert spec is not None
            rospy.logerr("mujoco_driver: %s: the arm stopped; commands are ignored until %s is called",
                         reflex.reason, spec.recovery_action)

    def reset(self) -> None:
        """Under the lock, after the simulation's reset: back at the start, so no reflex or stop either."""
        if self._emu.reset_stops() and self._safety_pubs is not None:
            self._publish_safety()

    # ------------------------------------------------------ services and action
    def _on_recovery(self, _goal: Any) -> None:
        with self._lock:
            recovered = self._emu.recover()
        if recovered:  # the next robot state says so
            rospy.loginfo("mujoco_driver: error recovery: the arm takes commands again")
        self._recovery.set_succeeded()

    def _on_unlock(self, _req: Any) -> TriggerResponse:
        return self._recovery_step(self._emu.unlock, "unlock_protective_stop")

    def _on_play(self, _req: Any) -> TriggerResponse:
        return self._recovery_step(self._emu.play, "program start")

    def _recovery_step(self, step: Callable[[], tuple[bool, str]], what: str) -> TriggerResponse:
        """One dashboard step of the protective stop's recovery: its answer, the new state published."""
        with self._lock:
            ok, answer = step()
        if ok:
            self._publish_safety()
        rospy.loginfo("mujoco_driver: %s: %s", what, answer)
        return TriggerResponse(success=ok, message=answer)

    def _on_list_controllers(self, _req: Any) -> Any:
        from controller_manager_msgs.msg import ControllerState, HardwareInterfaceResources
        from controller_manager_msgs.srv import ListControllersResponse

        with self._lock:
            listing = self._emu.controllers.listing()
        states = []
        for spec, state, joints in listing:
            claimed = ([HardwareInterfaceResources(spec.hardware_interface, joints)]
                       if spec.hardware_interface else [])
            states.append(ControllerState(name=spec.name, state=state, type=spec.type,
                                          claimed_resources=claimed))
        return ListControllersResponse(controller=states)

    def _on_switch_controller(self, req: Any) -> Any:
        from controller_manager_msgs.srv import SwitchControllerResponse

        with self._lock:
            result = self._emu.switch(list(req.start_controllers), list(req.stop_controllers), req.strictness)
            running = self._emu.controllers.running()
        if result.ok:
            rospy.loginfo("mujoco_driver: switched controllers: started %s, stopped %s; running %s%s",
                          result.started, result.stopped, running,
                          f" ({result.message})" if result.message else "")
        else:
            rospy.logerr("mujoco_driver: switch_controller refused: %s", result.message)
        return SwitchControllerResponse(ok=result.ok)

    def _on_zero(self, _req: Any) -> TriggerResponse:
        with self._lock:
            self._emu.zero()
        return TriggerResponse(success=True, message="the force/torque sensor reads zero now")


def _message_class(type_name: str) -> type:
    """A message (or action) class by its ``package/Name``.

    Raises:
        ProfileError: It is not installed.
    """
    cls: type | None = roslib.message.get_message_class(type_name)
    if cls is None:
        raise ProfileError(f"driver profile: message type {type_name!r} is not installed")
    return cls


def _set_field(msg: Any, path: str, value: object) -> None:
    """Set a field given by a dotted path (``current_errors.cartesian_reflex``)."""
    *parents, name = path.split(".")
    setattr(functools.reduce(getattr, parents, msg), name, value)
