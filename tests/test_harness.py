"""The test harness itself: private master, real topics, launch helpers and bags."""

import contextlib
import pathlib
import subprocess

import pytest
from geometry_msgs.msg import WrenchStamped
from harness.bags import read_bag, replay_bag, typestore, write_bag
from harness.launch import run_node
from harness.waiting import Collector, wait_until
from tf2_msgs.msg import TFMessage


def test_master_is_private_and_on_loopback(roscore):
    assert roscore.port != 11311
    assert roscore.uri == f"http://127.0.0.1:{roscore.port}"
    assert roscore.is_up()


def test_publish_and_receive_wrench(ros_node):
    rospy = ros_node
    collector = Collector("/harness_wrench", WrenchStamped)
    pub = rospy.Publisher("/harness_wrench", WrenchStamped, queue_size=10)
    wait_until(lambda: pub.get_num_connections() > 0, 10, "subscriber connection")
    sent = WrenchStamped()
    sent.header.frame_id = "ft_sensor"
    sent.wrench.force.z = -4.5
    pub.publish(sent)
    got = collector.wait_for(1)[0]
    assert got.header.frame_id == "ft_sensor"
    assert got.wrench.force.z == -4.5
    collector.close()
    pub.unregister()


def _wrench_bag(path, count=20, period_ns=10_000_000):
    ts = typestore()
    W = ts.types["geometry_msgs/msg/WrenchStamped"]
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    Wrench = ts.types["geometry_msgs/msg/Wrench"]
    V3 = ts.types["geometry_msgs/msg/Vector3"]
    msgs = []
    for i in range(count):
        stamp = 1_000_000_000 + i * period_ns
        msg = W(
            header=Header(seq=i, stamp=Time(sec=stamp // 10**9, nanosec=stamp % 10**9), frame_id="ft_sensor"),
            wrench=Wrench(force=V3(x=float(i), y=0.0, z=-1.0), torque=V3(x=0.0, y=0.0, z=0.5)),
        )
        msgs.append(("/harness_bag_wrench", "geometry_msgs/msg/WrenchStamped", stamp, msg))
    write_bag(path, msgs)


def test_bag_written_with_rosbags_reads_back_with_both_libraries(tmp_path):
    path = tmp_path / "wrench.bag"
    _wrench_bag(path)
    back = read_bag(path)
    assert [m.wrench.force.x for _, _, m in back] == [float(i) for i in range(20)]
    assert back[3][1] == 1_030_000_000

    rosbag = pytest.importorskip("rosbag")
    with rosbag.Bag(str(path)) as bag:
        got = [(topic, msg.wrench.force.x, t.to_nsec()) for topic, msg, t in bag.read_messages()]
    assert got[5] == ("/harness_bag_wrench", 5.0, 1_050_000_000)
    assert len(got) == 20


def test_replay_bag_into_live_topic(ros_node, tmp_path):
    path = tmp_path / "wrench.bag"
    _wrench_bag(path)
    collector = Collector("/harness_bag_wrench", WrenchStamped)
    sent = replay_bag(path)
    assert sent == 20
    msgs = collector.wait_for(20, timeout=10)
    assert [m.wrench.force.x for m in msgs] == [float(i) for i in range(20)]
    assert all(m.header.stamp.to_sec() > 1e9 + 100 for m in msgs), "restamped to now"
    collector.close()


def test_run_node_starts_and_stops_a_real_node(ros_node):
    with run_node(
        "tf2_ros", "static_transform_publisher", args=["0", "0", "1", "0", "0", "0", "base", "harness_frame"]
    ) as node:
        node.wait_for_topic("/tf_static", timeout=20)
        collector = Collector("/tf_static", TFMessage)

        def ours():  # /tf_static is latched: other tests' static publishers may answer too
            transforms = [t for m in list(collector.msgs) for t in m.transforms]
            return [t for t in transforms if t.child_frame_id == "harness_frame"]

        wait_until(lambda: bool(ours()), 10, "the harness_frame transform")
        assert ours()[0].transform.translation.z == 1.0
        collector.close()
    assert node.proc.poll() is not None, "node stopped when the context ended"


def test_a_killed_node_leaves_nothing_registered_for_the_next_one(ros_node):
    """A node killed before it could unregister (SIGKILL after the stop timeout) is cleaned from the master
    when its context ends (`rosnode cleanup`): left there, its name and API made the master shut down a later
    node that got the same port (a panda replay test's named_poses died so)."""
    import os
    import signal
    import xmlrpc.client

    master = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])

    def registered() -> set[str]:
        state = master.getSystemState("/test")[2]
        return {node for kind in state for _name, nodes in kind for node in nodes}

    with run_node("rostopic", "rostopic", args=["pub", "-r", "10", "/harness_killed", "std_msgs/Empty"],
                  name="harness_killed") as node:
        node.wait_for_topic("/harness_killed", timeout=20)
        os.killpg(node.proc.pid, signal.SIGKILL)
        node.proc.wait()
        assert "/harness_killed" in registered()  # what the master keeps of a killed node
    assert "/harness_killed" not in registered()
    assert master.lookupNode("/test", "/harness_killed")[0] != 1


def test_a_stale_node_from_outside_the_harness_is_forgotten_before_the_next_launch(ros_node):
    """A registration whose node is gone (its API refuses connections) and which no harness launch made is
    forgotten before the next launch starts: a new node given that API's port by the OS would otherwise be
    shut down when a node of the stale name registers (named_poses' FollowJointTrajectory tests lost theirs
    so)."""
    import os
    import socket
    import xmlrpc.client

    master = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])
    with socket.socket() as probe:  # a port nothing listens on: the stale node's API
        probe.bind(("127.0.0.1", 0))
        dead_api = f"http://127.0.0.1:{probe.getsockname()[1]}/"
    topic, kind = "/harness_stale_topic", "std_msgs/Empty"
    assert master.registerPublisher("/harness_stale", topic, kind, dead_api)[0] == 1
    assert master.lookupNode("/test", "/harness_stale")[0] == 1
    identity = ["0", "0", "0", "0", "0", "0", "a", "b"]
    with run_node("tf2_ros", "static_transform_publisher", args=identity):
        assert master.lookupNode("/test", "/harness_stale")[0] != 1


def test_launch_waits_report_a_missing_topic(ros_node):
    identity = ["0", "0", "0", "0", "0", "0", "a", "b"]
    with run_node("tf2_ros", "static_transform_publisher", args=identity) as node:
        with pytest.raises(AssertionError, match="topic /never_published"):
            node.wait_for_topic("/never_published", timeout=0.5)


def test_roslaunch_is_available():
    assert subprocess.run(["roslaunch", "--help"], capture_output=True).returncode == 0


def test_with_env_passes_the_command_its_own_arguments():
    """`scripts/with_env CMD --help`: catkin's setup script must not see (and choke on) the command's
    arguments; the command gets them all, unchanged, and runs in the built workspace."""
    root = pathlib.Path(__file__).resolve().parents[1]
    script = 'printf "%s|" "$@"; echo "$ROS_PACKAGE_PATH"'
    command = [str(root / "scripts/with_env"), "bash", "-c", script, "cmd", "--help", "--extend", "a b"]
    out = subprocess.run(command, capture_output=True, text=True, check=True, timeout=30)
    args, package_path = out.stdout.strip().split("\n")[-1].rsplit("|", 1)
    assert args == "--help|--extend|a b"
    assert str(root / "src") in package_path
    assert out.stderr == ""


def test_a_stop_leaves_no_process_below_the_launch_even_in_a_session_of_its_own():
    """roslaunch starts each node with setsid: a group signal misses it. A parent that ignores SIGINT is
    killed after the timeout, and the child it started in its own session goes with it."""
    import os
    import signal

    from harness.process import _started, stop_process_group

    parent = subprocess.Popen(["bash", "-c", "trap '' INT; setsid sleep 300 & echo $!; wait"],
                              stdout=subprocess.PIPE, text=True, start_new_session=True)
    child = int(parent.stdout.readline())
    assert _started(child) is not None
    try:
        stop_process_group(parent, timeout=0.5)
        assert _started(child) is None, "the node-like child outlived its stopped parent"
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.kill(child, signal.SIGKILL)
