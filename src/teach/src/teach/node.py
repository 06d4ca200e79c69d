"""program_server: records hand-guided motions as programs and serves them (see the package README).

Thin over `teach.recorder` and `teach.program`: subscribers keep the latest joint state and wrench, a timer at
`~rate` samples them with the tool pose from tf, services start, mark, stop and manage recordings.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import threading
import xml.etree.ElementTree as ET
from collections.abc import Sequence

import rosbag
import rospy
import tf2_ros
from compliant_common.diagnostics import OK, Report
from compliant_common.ros_diagnostics import DiagnosticsPublisher
from compliant_common.ros_tf_prefix import for_this_node
from compliant_common.ros_time import MonotonicTimer, TimerEvent, timer
from compliant_control_msgs.srv import (
    ListPrograms,
    ListProgramsRequest,
    ListProgramsResponse,
    ProgramCommand,
    ProgramCommandRequest,
    ProgramCommandResponse,
    RecordProgram,
    RecordProgramRequest,
    RecordProgramResponse,
)
from geometry_msgs.msg import PoseStamped, WrenchStamped
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger, TriggerRequest, TriggerResponse

from teach.params import TeachParamError, TeachSettings, load_settings
from teach.program import ProgramError, ProgramStore, check_name
from teach.recorder import Recorder
from teach.replay_server import ReplayServer

__all__ = ["TeachNode", "main", "robot_name"]

_TF_ERRORS = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)


def robot_name(description: str) -> str:
    """The `<robot name=...>` of a URDF ('' when it has none or is not XML)."""
    try:
        return ET.fromstring(description).get("name", "")
    except ET.ParseError:
        return ""


class TeachNode:
    """See the module docstring; every recorder call holds `_lock`."""

    def __init__(self, s: TeachSettings, robot: str, base_frame: str, tip_frame: str) -> None:
        self.settings = s
        self.store = ProgramStore(s.programs_dir)
        self.recorder = Recorder(robot, base_frame, tip_frame, s.rate, s.position_tolerance,
                                 s.angle_tolerance)
        self._lock = threading.Lock()
        self._joints: JointState | None = None
        self._wrench: WrenchStamped | None = None
        self._bag: rosbag.Bag | None = None
        self._bag_path = ""
        self._warn_after = 0.0  # a missing tool pose is worth a warning from then on (tf needs a moment)
        self._tf = tf2_ros.Buffer()
        self._listener: tf2_ros.TransformListener | None = None
        self._pose = PoseStamped()
        self._prefix = for_this_node()  # the robot's frames on tf and in messages; programs keep bare names
        self._pose.header.frame_id = self._prefix.add(base_frame)
        # Inputs only while recording: idle, the node costs the stack nothing (no 500 Hz deserialising).
        self._subs: list[rospy.Subscriber] = []
        self._timer: MonotonicTimer | rospy.Timer | None = None
        self._services = [
            rospy.Service("~record", RecordProgram, self._on_record),
            rospy.Service("~keyframe", Trigger, self._on_keyframe),
            rospy.Service("~stop", Trigger, self._on_stop),
            rospy.Service("~list", ListPrograms, self._on_list),
            rospy.Service("~show", ProgramCommand, self._on_show),
            rospy.Service("~delete", ProgramCommand, self._on_delete),
        ]
        self.replay = ReplayServer(s, self.store, robot, base_frame, tip_frame, self._tf, self._listen_tf,
                                   lambda: self.recorder.recording)
        self._health = DiagnosticsPublisher(self._health_report)

    def _health_report(self) -> Report:
        """/diagnostics: recording (with the samples so far), replaying (with its progress), or idle; the
        folder of the programs. Every fault here is a request's answer, so the level stays OK."""
        report = Report(rospy.get_name())
        with self._lock:
            name, count = self.recorder.name, self.recorder.count
        replaying = self.replay.describe()
        report.check(OK, f"recording '{name}' ({count} samples)" if name else replaying or "idle")
        report.value("programs_dir", self.store.folder)
        return report

    def _listen_tf(self) -> None:
        """tf from now on (the first recording or replay starts it; idle before)."""
        if self._listener is None:
            self._listener = tf2_ros.TransformListener(self._tf)

    def _listen(self) -> None:
        s = self.settings
        self._joints = self._wrench = None
        self._listen_tf()
        self._subs = [
            rospy.Subscriber(s.joint_states_topic, JointState, self._on_joints, queue_size=1),
            rospy.Subscriber(s.wrench_topic, WrenchStamped, self._on_wrench, queue_size=1),
        ]
        self._warn_after = rospy.get_time() + 1.0
        self._timer = timer(1.0 / s.rate, self._on_sample)

    def _unlisten(self) -> None:
        if self._timer is not None:
            self._timer.shutdown()
            self._timer = None
        for sub in self._subs:
            sub.unregister()
        self._subs = []

    # --- inputs ---
    def _on_joints(self, msg: JointState) -> None:
        self._joints = msg
        self._keep(self.settings.joint_states_topic, msg)

    def _on_wrench(self, msg: WrenchStamped) -> None:
        self._wrench = msg
        self._keep(self.settings.wrench_topic, msg)

    def _keep(self, topic: str, msg: JointState | WrenchStamped) -> None:
        """Into the raw stream's bag, when one is being kept."""
        if self._bag is not None:
            with self._lock:
                if self._bag is not None:  # it may have closed meanwhile
                    self._bag.write(topic, msg)

    def _on_sample(self, _event: TimerEvent | None) -> None:
        rec = self.recorder
        if not rec.recording:
            return
        joints, wrench = self._joints, self._wrench
        if joints is None:
            return
        try:
            tf = self._tf.lookup_transform(self._prefix.add(rec.base_frame), self._prefix.add(rec.tip_frame),
                                           rospy.Time(0))
        except _TF_ERRORS as err:
            if 0.0 < self._warn_after < rospy.get_time():
                self._warn_after = 0.0
                rospy.logwarn("teach: no tool pose (%s -> %s): %s", rec.base_frame, rec.tip_frame, err)
            return
        p, q = tf.transform.translation, tf.transform.rotation
        w = (0.0,) * 6
        if wrench is not None:
            f, m = wrench.wrench.force, wrench.wrench.torque
            w = (f.x, f.y, f.z, m.x, m.y, m.z)
        # The pose's own time, not this timer's: on a busy machine the timer fires late and the newest tf
        # is older than now, and pairing the two put a replay's speed off by tens of % between waypoints.
        t = tf.header.stamp.to_sec() or rospy.get_time()
        with self._lock:
            rec.add(t, joints.name, joints.position, (p.x, p.y, p.z), (q.x, q.y, q.z, q.w), w)
            if self._bag is not None:
                pose = self._pose
                pose.header.stamp = tf.header.stamp
                pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = p.x, p.y, p.z
                pose.pose.orientation = q
                self._bag.write("teach/tool_pose", pose)

    # --- services ---
    def _on_record(self, req: RecordProgramRequest) -> RecordProgramResponse:
        with self._lock:
            try:
                name = check_name(req.name)
                if os.path.exists(self.store.path(name)) and not req.overwrite:
                    raise ProgramError(f"program '{name}' exists: choose another name, delete it, or set "
                                       "overwrite")
                self.recorder.start(name, rospy.get_time())
            except ProgramError as err:
                return RecordProgramResponse(success=False, message=str(err))
            self._overwrite = bool(req.overwrite)
            if req.keep_bag:
                os.makedirs(self.store.folder, exist_ok=True)
                self._bag_path = os.path.join(self.store.folder, name + ".bag")
                self._bag = rosbag.Bag(self._bag_path, "w")
            self._listen()
        rate = self.settings.rate
        message = f"recording '{name}' at {rate:g} Hz"
        if req.keep_bag:
            message += f", raw stream into {self._bag_path}"
        rospy.loginfo("teach: %s", message)
        return RecordProgramResponse(success=True, message=message)

    def _on_keyframe(self, _req: TriggerRequest) -> TriggerResponse:
        with self._lock:
            try:
                n = self.recorder.keyframe()
            except ProgramError as err:
                return TriggerResponse(success=False, message=str(err))
        return TriggerResponse(success=True, message=f"keyframe {n} marked at the next sample")

    def _on_stop(self, _req: TriggerRequest) -> TriggerResponse:
        if self.recorder.recording:
            self._unlisten()  # outside the lock: a sample in progress finishes first
        with self._lock:
            bag, self._bag = self._bag, None
            if bag is not None:
                bag.close()
            try:
                program = self.recorder.finish(self._bag_path if bag is not None else "")
                path = self.store.save(program, overwrite=getattr(self, "_overwrite", False))
            except ProgramError as err:
                return TriggerResponse(success=False, message=f"not saved: {err}")
            finally:
                self._bag_path = ""
        message = f"saved {program.summary()} to {path}"
        rospy.loginfo("teach: %s", message)
        return TriggerResponse(success=True, message=message)

    def _on_list(self, _req: ListProgramsRequest) -> ListProgramsResponse:
        names, summaries = self.store.names(), []
        for name in names:
            try:
                summaries.append(self.store.load(name).summary())
            except ProgramError as err:
                summaries.append(f"{name}: unreadable: {err}")
        return ListProgramsResponse(names=names, summaries=summaries, folder=self.store.folder)

    def _on_show(self, req: ProgramCommandRequest) -> ProgramCommandResponse:
        try:
            program = self.store.load(req.name)
        except ProgramError as err:
            return ProgramCommandResponse(success=False, message=str(err))
        return ProgramCommandResponse(success=True, message=program.to_yaml())

    def _on_delete(self, req: ProgramCommandRequest) -> ProgramCommandResponse:
        try:
            path = self.store.delete(req.name)
        except ProgramError as err:
            return ProgramCommandResponse(success=False, message=str(err))
        bag = path[:-5] + ".bag"
        if os.path.exists(bag):
            os.remove(bag)
        return ProgramCommandResponse(success=True, message=f"deleted {path}")

    def shutdown(self) -> None:
        self._unlisten()
        with self._lock:
            if self._bag is not None:
                self._bag.close()
                self._bag = None


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `rosrun teach program_server` (node name `teach`); 1 on a bad configuration."""
    rospy.init_node("teach", argv=list(sys.argv if argv is None else argv))
    try:
        s = load_settings(rospy.get_param("~", {}))
    except TeachParamError as err:
        rospy.logfatal("program_server: bad configuration, not starting: %s", err)
        return 1
    cc = rospy.resolve_name(s.contact_control_node) + "/"
    base = s.base_frame or str(rospy.get_param(cc + "fixed_frame", "base_link"))
    tip = s.tip_frame or str(rospy.get_param(cc + "eef_frame", "tool0"))
    robot = s.robot or robot_name(str(rospy.get_param("robot_description", "")))
    if not robot:
        rospy.logfatal("program_server: no robot name: set ~robot, or robot_description's <robot name>")
        return 1
    # A robot in a namespace keeps its programs apart: two arms of a cell teach under one ROS_HOME, and a
    # program recorded on one is refused on the other (README, Programs).
    ns = rospy.get_namespace().strip("/")
    if ns:
        s = dataclasses.replace(s, programs_dir=os.path.join(s.programs_dir, ns))
    node = TeachNode(s, robot, base, tip)
    rospy.on_shutdown(node.shutdown)
    rospy.loginfo("teach: robot %s, tool pose %s in %s, programs in %s", robot, tip, base, node.store.folder)
    rospy.spin()
    return 0
