"""Replaying a recording through the stack, exactly as the contact_control README's "Replay a recording"
says: record the wrench and joint states of the simulated UR5 while a human pushes, then bring up the
hardware launch file under sim time, set a follower BEFORE playback, and `rosbag play --clock`: the follower
waits for data, then follows the recorded push."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess

import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.msg import ControlLaw
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
from compliant_control_msgs.msg import ContactControlStatus
from compliant_control_msgs.srv import PushEEF, PushEEFRequest
from geometry_msgs.msg import TwistStamped, WrenchStamped
from harness.launch import run_launch
from harness.waiting import Collector, wait_until
from std_msgs.msg import Float64MultiArray


def _record(rospy, bag: str) -> None:
    """0.5 s at rest, a 10 N push up for 1 s, 0.5 s at rest, recorded from the running simulation."""
    with run_launch("ur5_custom", "sim.launch") as h:
        h.wait_for_topic("/wrench", timeout=40)
        h.wait_for_service("/mujoco_driver/push", timeout=40)
        wrenches = Collector("/wrench", WrenchStamped)
        recorder = subprocess.Popen(
            ["rosbag", "record", "-O", bag, "/wrench", "/joint_states", "__name:=replay_recorder"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
        )
        try:
            master = rospy.get_master()
            wait_until(lambda: any(
                "/replay_recorder" in nodes for topic, nodes in master.getSystemState()[2][1]
                if topic == "/wrench"), 20, "rosbag record to subscribe")
            wrenches.clear()
            wrenches.wait_for(250, 10)  # 0.5 s at 500 Hz
            push = PushEEFRequest(duration=1.0)
            push.wrench.force.z = 10.0
            assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success
            wrenches.clear()
            wrenches.wait_for(750, 10)  # the push, then 0.5 s at rest
        finally:
            wrenches.close()
            with contextlib.suppress(ProcessLookupError):
                os.killpg(recorder.pid, signal.SIGINT)  # rosbag writes its index on SIGINT
            recorder.wait(20)


def test_a_recording_replays_through_hardware_launch_with_a_law_set_before_playback(ros_node, tmp_path):
    rospy = ros_node
    bag = str(tmp_path / "push.bag")
    _record(rospy, bag)
    assert os.path.getsize(bag) > 100_000
    rospy.set_param("/use_sim_time", True)
    try:
        with run_launch("ur5_custom", "hardware.launch") as h:
            h.wait_for_service("/configure_cartesian_impedance", timeout=40)
            h.wait_for_topic("/jog_arm_server/status", timeout=40)
            status = Collector("/contact_control_node/status", ContactControlStatus)
            twists = Collector("/jog_arm_server/contact_cmds", TwistStamped)  # contact_control's
            commands = Collector("/joint_group_vel_controller/command", Float64MultiArray)
            try:
                req = ConfigureForceControlRequest()
                req.cart_impedance_params.damping.translational.z = 30.0
                req.direction_control_laws.z.type = ControlLaw.TYPE_FOLLOWER
                configure = rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)
                assert configure(req).success
                play = subprocess.run(["rosbag", "play", "--clock", "-q", bag], capture_output=True,
                                      timeout=60)
                assert play.returncode == 0, play.stderr[-2000:]
                up = [m.twist.linear.z for m in list(twists.msgs) if m.twist.linear.z > 0.0]
                assert max(up, default=0.0) > 0.1, h.output()[-3000:]  # 10 N / 30 = 0.33, clamped at 0.25
                assert all(m.twist.linear.z >= 0.0 for m in list(twists.msgs))  # never against the push
                assert any(any(m.data) for m in list(commands.msgs)), "jog_arm commanded nothing"
                last = status.last()
                assert last.move_active, last.message  # it waited for the data instead of ending
                print(f"\nreplayed {os.path.getsize(bag) / 1e6:.1f} MB: the follower (set before playback) "
                      f"reached {max(up):.3f} m/s up; jog_arm sent {len(commands.msgs)} joint commands")
            finally:
                for c in (status, twists, commands):
                    c.close()
    finally:
        rospy.delete_param("/use_sim_time")
