"""The demonstrations' connection to a live stack, through its public ROS interface only.

Services and topics used (all names are parameters of `run_demos`, defaults as the robot packages
wire them): contact_control's `configure_cartesian_impedance` (`configure_laws` for force tracking),
`~tare`, `~stop`, `~reset`, `~status`;
the MuJoCo driver's `~push`, `~reset`, `~eef_pose` and the wrist `wrench` topic; tf for the sensor's
orientation.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from dataclasses import dataclass

import numpy as np
import rospy
import tf2_ros
from cartesian_impedance_msgs.srv import ConfigureForceControl
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.tf_prefix import TfPrefix
from compliant_control_msgs.msg import ContactControlStatus, ContactEvent
from compliant_control_msgs.srv import (
    ConfigureLaws,
    MoveToNamedPose,
    PushEEF,
    PushEEFRequest,
    PushEEFResponse,
)
from contact_control.frames import quaternion_matrix
from contact_control.noise_floor import NoiseFloor
from contact_control.params import ContactControlSettings
from geometry_msgs.msg import PoseStamped, WrenchStamped
from std_srvs.srv import Trigger

from thesis_demos.analysis import Recording
from thesis_demos.law_requests import build_laws_request, build_request
from thesis_demos.scenarios import AxisLaw, Scenario

__all__ = ["Names", "Series", "StackClient"]


@dataclass(frozen=True)
class Names:
    """Where the stack's interfaces live, relative to this node's namespace (README, Namespaces)."""

    configure: str = "configure_cartesian_impedance"
    configure_laws: str = "configure_laws"
    contact_control: str = "contact_control_node"
    driver: str = "mujoco_driver"
    named_poses: str = "named_poses"  # its ~move_to brings the arm to "start" (else the driver's ~reset)
    teach: str = "teach"  # teach's program_server (teach and replay)
    wrench: str = "wrench"
    base_frame: str = ""  # empty: contact_control's ~fixed_frame
    tf_prefix: str = "tf_prefix"  # the parameter with the robot's tf prefix; relative: the nearest one up

    def within(self, ns: str) -> Names:
        """These names under the namespace `ns` (another robot's: a cell's arm)."""
        head = "/" + ns.strip("/") + "/"
        return dataclasses.replace(self, **{f.name: head + getattr(self, f.name).lstrip("/")
                                            for f in dataclasses.fields(self)
                                            if f.name != "base_frame" and getattr(self, f.name)})


class Series:
    """Thread-safe append-only time series of fixed width."""

    def __init__(self, width: int) -> None:
        self.t: list[float] = []
        self.v: list[tuple[float, ...]] = []
        self.width = width
        self.lock = threading.Lock()

    def add(self, t: float, values: tuple[float, ...]) -> None:
        with self.lock:
            self.t.append(t)
            self.v.append(values)

    def clear(self) -> None:
        with self.lock:
            self.t.clear()
            self.v.clear()

    def arrays(self, t0: float) -> tuple[np.ndarray, np.ndarray]:
        with self.lock:
            t = np.asarray(self.t, dtype=float) - t0
            v = np.asarray(self.v, dtype=float).reshape(-1, self.width)
        keep = t >= 0.0
        return t[keep], v[keep]


class StackClient:
    """The stack's ROS interface for the demonstrations, connected once: laws sent, pushes, the move's state,
    the tool's pose and the forces recorded as series."""

    def __init__(self, names: Names, timeout: float = 60.0) -> None:
        self.names = names
        cc, drv = names.contact_control, names.driver
        for service in (
            names.configure,
            names.configure_laws,
            f"{cc}/tare",
            f"{cc}/stop",
            f"{cc}/reset",
            f"{drv}/push",
            f"{drv}/reset",
        ):
            rospy.wait_for_service(service, timeout=timeout)
        self._configure = rospy.ServiceProxy(names.configure, ConfigureForceControl)
        self._configure_laws = rospy.ServiceProxy(names.configure_laws, ConfigureLaws)
        self._tare_service = rospy.ServiceProxy(f"{cc}/tare", Trigger)
        self._stop_service = rospy.ServiceProxy(f"{cc}/stop", Trigger)
        self._reset_safety = rospy.ServiceProxy(f"{cc}/reset", Trigger)
        self._push_service = rospy.ServiceProxy(f"{drv}/push", PushEEF)
        self._reset_sim = rospy.ServiceProxy(f"{drv}/reset", Trigger)
        self._move_to: rospy.ServiceProxy | None = None
        try:  # started by the same launch as the rest, so it is there by now or not at all
            rospy.wait_for_service(f"{names.named_poses}/move_to", timeout=5.0)
            self._move_to = rospy.ServiceProxy(f"{names.named_poses}/move_to", MoveToNamedPose)
        except rospy.ROSException:
            rospy.logwarn("thesis_demos: no %s/move_to: the driver's ~reset brings the arm to its start pose",
                          names.named_poses)
        self._base_frame = names.base_frame or rospy.get_param(
            f"{cc}/fixed_frame", ContactControlSettings.fixed_frame
        )
        self._tf = tf2_ros.Buffer()
        self._tf_listener = tf2_ros.TransformListener(self._tf)
        # Read once the services are up: a launch sets every parameter before it starts a node.
        absolute = names.tf_prefix.startswith("/")
        self._tf_prefix = (TfPrefix(str(rospy.get_param(names.tf_prefix, ""))) if absolute
                           else for_this_node())  # the robot's frames on tf
        eef = rospy.get_param(f"{cc}/eef_frame", ContactControlSettings.eef_frame)
        self._eef = self._tf_prefix.add(str(eef))  # the tool tip's full tf name
        self.pose = Series(3)
        self._status = Series(6)
        self._wrench = Series(3)
        self._status_lock = threading.Lock()
        self._last_status: ContactControlStatus | None = None
        self._move_ends: list[float] = []  # stamps of contact_control's move_ended events [s]
        self._sensor_rotation: np.ndarray | None = None
        self._subs = [
            rospy.Subscriber(f"{drv}/eef_pose", PoseStamped, self._on_pose, queue_size=100, tcp_nodelay=True),
            rospy.Subscriber(
                f"{cc}/status", ContactControlStatus, self._on_status, queue_size=100, tcp_nodelay=True
            ),
            rospy.Subscriber(names.wrench, WrenchStamped, self._on_wrench, queue_size=100, tcp_nodelay=True),
            rospy.Subscriber(f"{cc}/events", ContactEvent, self._on_event, queue_size=20, tcp_nodelay=True),
        ]
        self.wait(lambda: self.pose.t and self._last_status is not None, timeout, "eef_pose and status")

    # --- callbacks ---
    def _on_pose(self, msg: PoseStamped) -> None:
        p = msg.pose.position
        self.pose.add(msg.header.stamp.to_sec(), (p.x, p.y, p.z))

    def _on_status(self, msg: ContactControlStatus) -> None:
        f, v = msg.wrench.force, msg.velocity.linear
        self._status.add(msg.header.stamp.to_sec(), (f.x, f.y, f.z, v.x, v.y, v.z))
        with self._status_lock:
            self._last_status = msg

    def _on_event(self, msg: ContactEvent) -> None:
        if msg.type == ContactEvent.MOVE_ENDED:
            with self._status_lock:
                self._move_ends.append(msg.header.stamp.to_sec())

    def ended_at(self, seen: float) -> float:
        """When the move the runner saw end at `seen` [s, rospy time] ended: the last move_ended event's stamp
        up to then (its cycle), else `seen`. Polling status saw it up to a status period late, more on a busy
        machine, and the force's jolt as the tool stops then fell inside the judged window."""
        with self._status_lock:
            stamps = [t for t in self._move_ends if t <= seen]
        return stamps[-1] if stamps else seen

    def _on_wrench(self, msg: WrenchStamped) -> None:
        if self._sensor_rotation is None:
            return
        f = msg.wrench.force
        world = self._sensor_rotation @ np.array((f.x, f.y, f.z))
        self._wrench.add(msg.header.stamp.to_sec(), tuple(world))

    # --- helpers ---
    @staticmethod
    def wait(predicate, timeout: float, what: str) -> None:
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise TimeoutError(f"timed out waiting for {what}")
            time.sleep(0.01)

    def _update_sensor_rotation(self, sensor_frame: str) -> None:
        q = self._lookup(self._base(), self._tf_prefix.add(sensor_frame)).transform.rotation
        x, y, z, w = q.x, q.y, q.z, q.w
        # The wrench is read as contact_control reads it: its ft_*_direction sign flips first (a driver that
        # reports the wrench the robot exerts has all three -1 in its robot package's hardware YAML).
        signs = [self.contact_setting(f"ft_{a}_direction") for a in "xyz"]
        self._sensor_rotation = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        ) @ np.diag(signs)

    def settle(self, timeout: float = 10.0, window: float = 0.3, tolerance: float = 2e-4) -> None:
        """Waits until the tool has moved less than `tolerance` over `window` seconds."""

        self.pose.clear()
        self.wait(lambda: self.still(window, tolerance), timeout, "the arm to settle")

    def still(self, window: float = 0.3, tolerance: float = 2e-4) -> bool:
        """Whether the tool has moved less than `tolerance` [m] over the last `window` seconds recorded."""
        with self.pose.lock:
            if not self.pose.t or self.pose.t[-1] - self.pose.t[0] < window:
                return False
            since = self.pose.t[-1] - window
            recent = [v for t, v in zip(self.pose.t, self.pose.v, strict=True) if t > since]
        return float(np.ptp(np.asarray(recent), axis=0).max()) < tolerance

    def move_state(self) -> tuple[bool, dict[str, int]]:
        """(whether the move or its exceeded action, e.g. moving away, still runs; end condition per axis)."""
        with self._status_lock:
            status = self._last_status
        ends = {a.axis: a.end_condition for a in status.axes} if status else {}
        return bool(status and (status.move_active or status.reacting)), ends

    def start_tip(self) -> tuple[float, float, float]:
        """Returns the arm to its start pose, waits until still, and gives the tool tip [m]."""
        self._to_start()
        with self.pose.lock:
            return tuple(self.pose.v[-1])  # type: ignore[return-value]

    def _to_start(self) -> None:
        """Named pose `start` (a joint-space move, as on a real arm), else the driver's reset; then still."""
        self.stop()
        if self._move_to is not None:
            self.settle()  # the stop's last zero commands are through before the trajectory goes out
            result = self._move_to(name="start", speed_scale=1.0)
            if not result.success:
                raise RuntimeError(f"named pose 'start' failed: {result.message}")
        else:
            result = self._reset_sim()
            if not result.success:
                raise RuntimeError(f"driver reset failed: {result.message}")
        self.settle()

    # --- one scenario ---
    def prepare(self, sensor_frame: str) -> float:
        """The start pose, the safety reset, the sensor tared, the series cleared; returns when the tared
        sensor's baseline began: 0.3 s of it before anything moves is the recorded contact force's zero (the
        few ms of the configure call alone could leave a loaded machine without a wrench)."""
        self._to_start()
        self._reset_safety()
        self.tare()
        self._update_sensor_rotation(sensor_frame)
        for series in (self.pose, self._status, self._wrench):
            series.clear()
        baseline_t = rospy.get_time()
        time.sleep(0.3)
        return baseline_t

    def send(self, scenario: Scenario, laws: dict[str, AxisLaw]) -> None:
        """Sends laws through configure_laws when the scenario needs it, else the original service."""
        if scenario.uses_laws_service:
            try:
                self.send_laws(laws, scenario.exceeded_action)
            except RuntimeError as exc:
                raise RuntimeError(f"{scenario.name}: {exc}") from None
            return
        response = self._configure(build_request(scenario))
        if not response.success:
            raise RuntimeError(f"{scenario.name}: contact_control refused the request (see its ~status)")

    def tare(self) -> None:
        """contact_control's `~tare`: the sensor's offset measured where the arm is now.

        Raises:
            RuntimeError: With the node's reason, if it refused.
        """
        tare = self._tare_service()
        if not tare.success:
            raise RuntimeError(f"tare failed: {tare.message}")

    def send_laws(self, laws: dict[str, AxisLaw], exceeded_action: str = "stop") -> int:
        """Laws per axis through configure_laws (axes left out hold); returns how many moves had ended
        before (:meth:`wait_move_end`'s `before`).

        Raises:
            RuntimeError: With contact_control's reason, if it refused them.
        """
        with self._status_lock:
            before = len(self._move_ends)
        answer = self._configure_laws(build_laws_request(laws, exceeded_action))
        if not answer.success:
            raise RuntimeError(f"contact_control refused the laws: {answer.message}")
        return before

    def wait_move_end(self, before: int, timeout: float, what: str) -> None:
        """Waits for contact_control's move_ended event of the move sent after `before` had ended."""

        def ended() -> bool:
            with self._status_lock:
                return len(self._move_ends) > before

        self.wait(ended, timeout, what)

    def _lookup(self, target: str, source: str):
        """tf's transform from `source` to `target`, both full tf names."""
        return self._tf.lookup_transform(target, source, rospy.Time(0), rospy.Duration(5.0))

    def _base(self) -> str:
        """contact_control's fixed frame's full tf name."""
        return self._tf_prefix.add(self._base_frame)

    def world_pose(self, frame: str) -> tuple[np.ndarray, tuple[float, float, float, float]]:
        """The tool tip's (contact_control's `eef_frame`) position [m] and orientation (x, y, z, w) in the tf
        frame `frame`, taken as it is (a cell's `world`, above every arm's tf prefix)."""
        tf = self._lookup(frame, self._eef).transform
        t, q = tf.translation, tf.rotation
        return np.array([t.x, t.y, t.z]), (q.x, q.y, q.z, q.w)

    def sees(self, frame: str, sensor_frame: str) -> bool:
        """Whether tf has this robot's tool tip in the tf frame `frame` (taken as it is) and its sensor in
        contact_control's fixed frame: its robot_state_publisher is up and its frames hang from `frame`."""
        sensor = self._tf_prefix.add(sensor_frame)
        return bool(self._tf.can_transform(frame, self._eef, rospy.Time(0))
                    and self._tf.can_transform(self._base(), sensor, rospy.Time(0)))

    def tool_pose(self) -> tuple[np.ndarray, tuple[float, float, float, float]]:
        """The tool tip's pose in contact_control's fixed frame (where its laws' travel is measured)."""
        return self.world_pose(self._base())

    def in_base(self, frame: str, point: np.ndarray) -> np.ndarray:
        """`point` [m], given in the tf frame `frame` (taken as it is), in contact_control's fixed frame."""
        tf = self._lookup(self._base(), frame).transform
        t, q = tf.translation, tf.rotation
        R = np.asarray(quaternion_matrix(q.x, q.y, q.z, q.w))
        return R @ np.asarray(point, dtype=float) + np.array([t.x, t.y, t.z])

    def push(self, request: PushEEFRequest) -> PushEEFResponse:
        """The driver's `~push` (a simulated hand on the tool)."""
        return self._push_service(request)

    def stop(self) -> None:
        """contact_control's `~stop`: the move ends, the arm holds."""
        self._stop_service()

    @staticmethod
    def now() -> float:
        """ROS time [s]."""
        return rospy.get_time()

    @staticmethod
    def shutting_down() -> bool:
        return rospy.is_shutdown()

    def tip(self) -> np.ndarray:
        """The tool tip's newest position [m]."""
        with self.pose.lock:
            return np.asarray(self.pose.v[-1], dtype=float)

    def has_hole(self) -> bool:
        """Whether the simulated scene has the hole fixture (the driver's ground truth `~hole_pose`)."""
        return rospy.has_param(f"{self.names.driver}/hole_pose")

    def has_surface(self, kind: str) -> bool:
        """Whether the simulated scene has a finishing fixture of `kind` (the driver's `~surface`)."""
        truth = rospy.get_param(f"{self.names.driver}/surface", None)
        return isinstance(truth, dict) and truth.get("kind") == kind

    def contact_setting(self, name: str) -> float:
        """contact_control's parameter `name` as the node reads it (its default if unset)."""
        default = getattr(ContactControlSettings, name)
        return float(rospy.get_param(f"{self.names.contact_control}/{name}", default))

    def pose_residual(self) -> tuple[float, float]:
        """How far contact_control takes its sensor's offset to move over the workspace beyond the noise
        (force [N], torque [Nm]): its bias map's held-out residual, else its pose_offset_force / _torque.

        Raises:
            RuntimeError: The bias map file cannot be read (the node would not have started either).
        """
        from contact_control.bias_map import BiasMapError, load_bias_map

        path = str(rospy.get_param(f"{self.names.contact_control}/bias_map", ""))
        if path:
            try:
                loaded = load_bias_map(path)
            except BiasMapError as err:
                raise RuntimeError(str(err)) from err
            return loaded.residual_force, loaded.residual_torque
        return self.contact_setting("pose_offset_force"), self.contact_setting("pose_offset_torque")

    def noise_floor(self, timeout: float = 10.0) -> NoiseFloor | None:
        """contact_control's noise floor as its ~status reports it (measured while zeroing); None when it
        reports none (not zeroed, or an older node)."""

        def reported() -> bool:  # a noise floor, or zeroed without one
            with self._status_lock:
                status = self._last_status
            return status is not None and (len(status.noise_filtered) == 6
                                           or status.safety != ContactControlStatus.SAFETY_ZEROING)

        try:
            self.wait(reported, timeout, "contact_control's zeroing")
        except TimeoutError:
            return None
        with self._status_lock:
            status = self._last_status
        if status is None or len(status.noise_filtered) != 6:
            return None
        return NoiseFloor(tuple(status.noise_std), 0.0, 0, tuple(status.noise_filtered))

    def force(self, axis: str) -> float | None:
        """The controller's latest force [N] along `axis` (x, y or z; control frame), None before a status."""
        with self._status_lock:
            status = self._last_status
        return None if status is None else getattr(status.wrench.force, axis)

    def recording(
        self, t0: float, baseline_t: float, ends: dict[str, int], end_time: float | None
    ) -> Recording:
        pose_t, pose = self.pose.arrays(t0)
        status_t, status = self._status.arrays(t0)
        wrench_t_all, wrench_all = self._wrench.arrays(baseline_t)
        before = wrench_t_all < (t0 - baseline_t)
        bias = wrench_all[before].mean(axis=0) if np.any(before) else np.zeros(3)
        after = ~before
        return Recording(
            pose_t=pose_t,
            pose=pose,
            status_t=status_t,
            force=status[:, :3],
            command=status[:, 3:],
            wrench_t=wrench_t_all[after] - (t0 - baseline_t),
            contact_force=wrench_all[after] - bias,
            end_conditions=ends,
            move_end_time=end_time,
        )

    def close(self) -> None:
        for sub in self._subs:
            sub.unregister()
