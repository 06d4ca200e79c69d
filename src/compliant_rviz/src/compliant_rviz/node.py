"""stack_markers: the stack's state as visualization_msgs/MarkerArray for RViz (see the package README).

Listens to contact_control's ~status and ~path_reference and to the simulation's ~active_push, looks the tool
up in tf, and publishes ~markers at `~rate` (10 Hz) from a timer thread: never on the control path, and
nothing when nobody subscribes.
"""

from __future__ import annotations

import threading

import rospy
import tf2_ros
import yaml
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.ros_time import timer
from compliant_control_msgs.msg import ContactControlStatus, JogStatus, PathReference
from geometry_msgs.msg import Point, WrenchStamped
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from compliant_rviz.markers import AxisLine, Box, Trail, axis_text, cap_text, obstacle_box, velocity_arrow

__all__ = ["StackMarkers", "main"]

_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)
PUSH_METRES_PER_NEWTON = 0.02  # the push arrow: 10 N is 0.2 m long
TEXT_ABOVE = 0.25  # [m] the laws' text above the tool
REPLAYING = 0.5  # [s] a path reference newer than this: the tool's trail grows


def _colour(r: float, g: float, b: float, a: float = 1.0) -> ColorRGBA:
    return ColorRGBA(r=r, g=g, b=b, a=a)


class StackMarkers:
    """Subscribers, tf and the timer that publishes the markers."""

    def __init__(self) -> None:
        cc = rospy.get_param("~contact_control", "contact_control_node").rstrip("/")
        jog = rospy.get_param("~jog_arm", "jog_arm_server").rstrip("/")
        prefix = for_this_node()  # the robot's links on tf
        base = rospy.get_param("~base_frame", rospy.get_param(f"{cc}/fixed_frame", "base_link"))
        self.base = prefix.add(base)
        self.tip = prefix.add(rospy.get_param("~tip_frame", rospy.get_param(f"{cc}/eef_frame", "tool0")))
        self._lock = threading.Lock()
        self._status: ContactControlStatus | None = None
        self._jog: JogStatus | None = None
        self._push: WrenchStamped | None = None
        self._reference = Trail()
        self._tool = Trail()
        self._last_reference = -1e9
        scene = rospy.get_param("~scene_config", rospy.get_param("mujoco_driver/scene_config", ""))
        self._box = self._scene_box(scene)
        self._tf = tf2_ros.Buffer()
        self._listener = tf2_ros.TransformListener(self._tf)
        self._pub = rospy.Publisher("~markers", MarkerArray, queue_size=1)
        self._subs = [
            rospy.Subscriber(f"{cc}/status", ContactControlStatus, self._on_status, queue_size=1),
            rospy.Subscriber(f"{cc}/path_reference", PathReference, self._on_reference, queue_size=10),
            rospy.Subscriber(f"{jog}/status", JogStatus, self._on_jog, queue_size=1),
            rospy.Subscriber(rospy.get_param("~push_topic", "mujoco_driver/active_push"), WrenchStamped,
                             self._on_push, queue_size=1),
        ]
        self._timer = timer(1.0 / float(rospy.get_param("~rate", 10.0)), self._tick)

    @staticmethod
    def _scene_box(path: str) -> Box | None:
        if not path:
            return None
        try:
            with open(path, encoding="utf-8") as f:
                scene = yaml.safe_load(f) or {}
        except (OSError, yaml.YAMLError) as err:
            rospy.logwarn("stack_markers: scene %s not read (%s): no obstacle drawn", path, err)
            return None
        return obstacle_box(scene) if isinstance(scene, dict) else None

    # --- in ---
    def _on_status(self, msg: ContactControlStatus) -> None:
        with self._lock:
            self._status = msg

    def _on_jog(self, msg: JogStatus) -> None:
        with self._lock:
            self._jog = msg

    def _on_push(self, msg: WrenchStamped) -> None:
        with self._lock:
            self._push = msg

    def _on_reference(self, msg: PathReference) -> None:
        p = msg.pose.position
        t = rospy.get_time()
        with self._lock:
            self._reference.add(t, (p.x, p.y, p.z))
            self._last_reference = t

    def _tip_in(self, frame: str) -> tuple[float, float, float] | None:
        try:
            tf = self._tf.lookup_transform(frame, self.tip, rospy.Time(0))
        except _TF_ERRORS:
            return None
        v = tf.transform.translation
        return (v.x, v.y, v.z)

    # --- out ---
    def _tick(self, _event: object) -> None:
        if self._pub.get_num_connections() == 0:
            return
        now = rospy.get_time()
        tip = self._tip_in(self.base)
        with self._lock:
            status, push, jog = self._status, self._push, self._jog
            if tip is not None and now - self._last_reference < REPLAYING:
                self._tool.add(now, tip)
            reference, tool = list(self._reference.points), list(self._tool.points)
        markers = MarkerArray()
        stamp = rospy.Time.now()

        def marker(ns: str, kind: int, frame: str, colour: ColorRGBA) -> Marker:
            m = Marker(ns=ns, id=0, type=kind, action=Marker.ADD, color=colour)
            m.header.frame_id, m.header.stamp = frame, stamp
            m.pose.orientation.w = 1.0
            markers.markers.append(m)
            return m

        def hide(ns: str) -> None:
            m = marker(ns, Marker.ARROW, self.base, _colour(0, 0, 0, 0))
            m.action = Marker.DELETE

        if status is not None:
            lines = [AxisLine(a.axis, a.law_name, a.force, a.velocity, a.end_condition_name, a.reacting)
                     for a in status.axes]
            text = marker("laws", Marker.TEXT_VIEW_FACING, self.base, _colour(1, 1, 1))
            text.text = axis_text(lines, status.safety_name, status.message)
            cap = "" if jog is None else cap_text(jog.speed_cap, jog.body_region,
                                                  jog.code == JogStatus.COLLABORATIVE_SPEED_CAP)
            if cap:
                text.text += "\n" + cap
            text.scale.z = 0.03
            if tip is not None:
                text.pose.position = Point(tip[0], tip[1], tip[2] + TEXT_ABOVE)
            frame = status.header.frame_id or self.base
            local = self._tip_in(frame)
            v = status.velocity.linear
            arrow = velocity_arrow(local, (v.x, v.y, v.z)) if local is not None else None
            if arrow is None:
                hide("velocity")
            else:
                m = marker("velocity", Marker.ARROW, frame, _colour(0.1, 0.4, 1.0))
                m.points = [Point(*arrow[0]), Point(*arrow[1])]
                m.scale.x, m.scale.y, m.scale.z = 0.008, 0.016, 0.02
        if self._box is not None:
            box = marker("obstacle", Marker.CUBE, self.base, _colour(0.8, 0.2, 0.2, 0.6))
            box.pose.position = Point(*self._box.position)
            o = box.pose.orientation
            o.x, o.y, o.z, o.w = self._box.quaternion()
            box.scale.x, box.scale.y, box.scale.z = self._box.size
        force = push.wrench.force if push is not None else None
        if push is not None and force is not None and tip is not None and (force.x or force.y or force.z):
            m = marker("push", Marker.ARROW, push.header.frame_id or self.base, _colour(1.0, 0.6, 0.0))
            k = PUSH_METRES_PER_NEWTON
            m.points = [Point(tip[0] - k * force.x, tip[1] - k * force.y, tip[2] - k * force.z), Point(*tip)]
            m.scale.x, m.scale.y, m.scale.z = 0.01, 0.02, 0.03
        else:
            hide("push")
        for ns, points, colour in (("reference path", reference, _colour(0.2, 0.9, 0.2)),
                                   ("tool path", tool, _colour(1.0, 0.9, 0.1))):
            if len(points) < 2:
                hide(ns)
                continue
            m = marker(ns, Marker.LINE_STRIP, self.base, colour)
            m.points = [Point(*p) for p in points]
            m.scale.x = 0.002
        self._pub.publish(markers)


def main() -> int:
    rospy.init_node("stack_markers")
    StackMarkers()
    rospy.spin()
    return 0
