"""named_poses on the simulated UR5: move_to goes there within the joint limits, and refuses what it must."""

import threading

import numpy as np
import pytest
from harness.launch import run_launch, run_node
from harness.waiting import Collector, wait_until


@pytest.fixture(scope="module")
def stack(ros_node):
    # Another robot's launch on the same master leaves its poses behind (seen: the Panda's before the UR5's):
    # they must not reach this one's named_poses.
    ros_node.set_param("/named_poses/poses/start/other_robot_joint", 1.0)
    with run_launch("ur5_custom", "sim.launch") as launched:
        try:
            launched.wait_for_service("/named_poses/move_to", timeout=60)
            launched.wait_for_service("/configure_cartesian_impedance", timeout=60)
        except AssertionError as exc:
            raise AssertionError(f"{exc}\n{launched.output()[-6000:]}") from None
        yield launched


def _proxy():
    import rospy
    from compliant_control_msgs.srv import MoveToNamedPose

    return rospy.ServiceProxy("/named_poses/move_to", MoveToNamedPose)


def test_move_to_home_arrives_within_the_joint_velocity_limit(stack):
    import rospy
    import yaml
    from rospkg import RosPack
    from sensor_msgs.msg import JointState

    config = yaml.safe_load(open(RosPack().get_path("ur5_custom") + "/config/named_poses.yaml"))
    home = config["poses"]["home"]
    states = Collector("/joint_states", JointState, queue_size=1000)
    try:
        states.wait_for(1)
        answer = _proxy()(name="home", speed_scale=1.0)
        answer_time = rospy.Time.now()
        assert answer.success, answer.message
        # The first state measured after the answer (this process may receive them late on a busy machine).
        wait_until(lambda: states.last().header.stamp >= answer_time, 10, "a joint state after the answer")
        after = next(m for _, m in states.timed() if m.header.stamp >= answer_time)
        at = dict(zip(after.name, after.position, strict=True))
        assert max(abs(at[j] - q) for j, q in home.items()) < 0.01
        speeds = np.array([m.velocity for _, m in states.timed()])
        assert np.max(np.abs(speeds)) <= config["max_velocity"] * 1.05
        assert np.max(np.abs(speeds)) > 0.3 * config["max_velocity"], "it moved, at a useful speed"
        back = _proxy()(name="start", speed_scale=0.5)
        assert back.success, back.message
    finally:
        states.close()


def test_unknown_pose_is_refused_with_the_known_names(stack):
    answer = _proxy()(name="lunch", speed_scale=1.0)
    assert not answer.success
    assert "known: ['home', 'start']" in answer.message


def _start_a_slow_contact_move() -> None:
    """A contact move that runs until it is stopped (contact_control's ~status then says move_active): a
    follower on X, so the arm stands still unless pushed. A compliant move that ends on its travel ended
    before a node started on a loaded machine asked its question (CI: the late node then rightly moved)."""
    import rospy
    from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest

    req = ConfigureForceControlRequest()
    req.direction_control_laws.x.type = 1  # follower
    req.cart_impedance_params.damping.translational.x = 30.0
    assert rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)(req).success


def test_refused_while_a_contact_move_runs(stack):
    import rospy
    from compliant_control_msgs.msg import ContactControlStatus
    from std_srvs.srv import Trigger

    _start_a_slow_contact_move()
    try:
        status = "/contact_control_node/status"
        wait_until(
            lambda: rospy.wait_for_message(status, ContactControlStatus, 5).move_active, 10, "a contact move"
        )
        answer = _proxy()(name="home", speed_scale=1.0)
        assert not answer.success
        assert "a contact move is running" in answer.message
    finally:
        rospy.ServiceProxy("/contact_control_node/stop", Trigger)()


def test_a_fresh_named_poses_node_refuses_during_a_contact_move_it_has_not_heard_of_yet(stack):
    """Asked right after start-up, before its status subscription has delivered anything, named_poses waits
    for contact_control's status instead of taking silence for "no contact move" (the test above
    cannot see this: by its request the status has arrived)."""
    import rospy
    from compliant_control_msgs.msg import ContactControlStatus
    from compliant_control_msgs.srv import MoveToNamedPose
    from rospkg import RosPack
    from std_srvs.srv import Trigger

    _start_a_slow_contact_move()
    params = {"config": RosPack().get_path("ur5_custom") + "/config/named_poses.yaml",
              "trajectory_topic": "/arm_controller/command_unused", "joint_states_topic": "/joint_states"}
    try:
        wait_until(lambda: rospy.wait_for_message("/contact_control_node/status", ContactControlStatus,
                                                  5).move_active, 10, "a contact move")
        with run_node("named_poses", "named_pose_server", params=params, name="late_poses") as late:
            late.wait_for_service("/late_poses/move_to", timeout=30)
            answer = rospy.ServiceProxy("/late_poses/move_to", MoveToNamedPose)(name="home", speed_scale=1.0)
            still = rospy.wait_for_message("/contact_control_node/status", ContactControlStatus, 5)
            assert still.move_active, f"the contact move ended before the question: {still.message}"
            assert not answer.success and "a contact move is running" in answer.message, answer.message
    finally:
        rospy.ServiceProxy("/contact_control_node/stop", Trigger)()


def test_a_request_before_the_first_joint_state_waits_for_it_or_says_which_topic_is_silent(stack):
    """Right after start-up a request can come before the driver's first state reaches the node."""
    import rospy
    import yaml
    from compliant_control_msgs.srv import MoveToNamedPose
    from rospkg import RosPack
    from sensor_msgs.msg import JointState

    path = RosPack().get_path("ur5_custom") + "/config/named_poses.yaml"
    start = yaml.safe_load(open(path))["poses"]["start"]
    topic = "/late_joint_states"
    params = {"config": path, "joint_states_topic": topic, "state_wait": 1.5,
              "trajectory_topic": "/late_trajectory"}
    with run_node("named_poses", "named_pose_server", params=params, name="late_poses") as node:
        node.wait_for_service("/late_poses/move_to", timeout=30)
        move_to = rospy.ServiceProxy("/late_poses/move_to", MoveToNamedPose)
        t0 = rospy.get_time()
        silent = move_to(name="start", speed_scale=1.0)
        assert not silent.success
        assert topic in silent.message and "1.5 s" in silent.message, silent.message
        assert rospy.get_time() - t0 >= 1.4, "it waited before refusing"

        pub = rospy.Publisher(topic, JointState, queue_size=1)

        answered = threading.Event()

        def late_states() -> None:  # the driver comes up 0.5 s after the request
            answered.wait(0.5)
            while not answered.is_set():
                pub.publish(JointState(name=list(start), position=list(start.values())))
                answered.wait(0.05)

        threading.Thread(target=late_states, daemon=True).start()
        try:
            answer = move_to(name="start", speed_scale=1.0)
        finally:
            answered.set()
        assert answer.success, answer.message


def test_a_trajectory_waits_for_the_drivers_subscription_or_the_move_is_refused_naming_the_topic(stack):
    """A trajectory published before the driver's subscription has connected (right after start-up) is lost
    and the arm would not move at all: the move waits up to `~state_wait` for a subscriber, else refuses."""
    import rospy
    from compliant_control_msgs.srv import MoveToNamedPose
    from rospkg import RosPack
    from trajectory_msgs.msg import JointTrajectory

    topic = "/late_driver/command"
    params = {"config": RosPack().get_path("ur5_custom") + "/config/named_poses.yaml",
              "joint_states_topic": "/joint_states", "trajectory_topic": topic, "state_wait": 1.0,
              "settle_time": 0.2}
    with run_node("named_poses", "named_pose_server", params=params, name="late_poses") as node:
        node.wait_for_service("/late_poses/move_to", timeout=30)
        move_to = rospy.ServiceProxy("/late_poses/move_to", MoveToNamedPose)
        refused = move_to(name="home", speed_scale=1.0)
        assert not refused.success
        assert f"nothing subscribes to {topic} within 1 s" in refused.message, refused.message

        got: list[JointTrajectory] = []
        subs: list[rospy.Subscriber] = []
        answered = threading.Event()

        def subscribe_late() -> None:  # the driver's subscription connects 0.3 s after the request
            if not answered.wait(0.3):
                subs.append(rospy.Subscriber(topic, JointTrajectory, got.append))

        threading.Thread(target=subscribe_late, daemon=True).start()
        try:
            move_to(name="home", speed_scale=1.0)  # nothing moves the arm here: the answer is "did not reach"
        finally:
            answered.set()
            for sub in subs:
                sub.unregister()
        assert len(got) == 1 and got[0].points, "the trajectory reached the late subscriber"


def test_a_jog_held_during_a_move_is_paused_for_it_and_resumed_after(stack):
    """A key held down in keyboard.launch (twists streaming into jog_arm) while move_to runs: jog_arm's joint
    commands would replace the trajectory (the arm stayed 0.3 rad from the pose: "did not reach"). named_poses
    pauses jog_arm for the move (its answer comes once jog_arm is silent) and resumes it: the pose is reached,
    and afterwards the same stream moves the arm again."""
    import rospy
    import yaml
    from geometry_msgs.msg import PoseStamped, TwistStamped
    from harness.streams import Repeater
    from rospkg import RosPack
    from sensor_msgs.msg import JointState

    config = RosPack().get_path("ur5_custom") + "/config/named_poses.yaml"
    home = yaml.safe_load(open(config))["poses"]["home"]
    pub = rospy.Publisher("/jog_arm_server/delta_jog_cmds", TwistStamped, queue_size=1, tcp_nodelay=True)
    pose = Collector("/mujoco_driver/eef_pose", PoseStamped)
    states = Collector("/joint_states", JointState, queue_size=10)
    twist = TwistStamped()
    twist.header.frame_id = "base_link"
    twist.twist.linear.y = 0.02
    stream = Repeater(pub)

    def y() -> float:
        return pose.last().pose.position.y

    try:
        wait_until(lambda: pub.get_num_connections() > 0, 10, "jog_arm to subscribe")
        pose.wait_for(1, 10)
        y0 = y()
        stream.start(twist, rate=50.0)
        wait_until(lambda: y() > y0 + 0.002, 10, "the jog to move the arm")
        answer = _proxy()(name="home", speed_scale=1.0)
        assert answer.success, answer.message
        assert "/jog_arm_server paused for the move, then resumed" in answer.message
        at = dict(zip(states.last().name, states.last().position, strict=True))
        assert max(abs(at[j] - q) for j, q in home.items()) < 0.01
        y1 = y()
        wait_until(lambda: y() > y1 + 0.002, 10, "the jog to move the arm again after the move")
    finally:
        stream.stop()
        pose.close()
        states.close()
        pub.unregister()
    rospy.sleep(0.3)  # jog_arm stale and silent before the trajectory back
    back = _proxy()(name="start", speed_scale=1.0)
    assert back.success, back.message


def test_move_to_joints_goes_to_given_positions_and_refuses_missing_or_out_of_limit_ones(stack):
    import rospy
    import yaml
    from compliant_control_msgs.srv import MoveToJoints
    from rospkg import RosPack
    from sensor_msgs.msg import JointState

    config = yaml.safe_load(open(RosPack().get_path("ur5_custom") + "/config/named_poses.yaml"))
    start = config["poses"]["start"]
    names = list(start)
    goal = [q + (0.1 if i == 0 else 0.0) for i, q in enumerate(start.values())]  # the base turned 0.1 rad
    move = rospy.ServiceProxy("/named_poses/move_to_joints", MoveToJoints)
    answer = move(joint_names=[*names, "a_gripper_joint"], positions=[*goal, 0.02], speed_scale=1.0,
                  label="the start of program x")
    assert answer.success and answer.message.startswith("at the start of program x after"), answer.message
    state = rospy.wait_for_message("/joint_states", JointState, timeout=10)
    at = dict(zip(state.name, state.position, strict=True))
    assert max(abs(at[j] - q) for j, q in zip(names, goal, strict=True)) < 0.01
    missing = move(joint_names=names[1:], positions=goal[1:], speed_scale=1.0, label="")
    assert not missing.success and f"no position for ['{names[0]}']" in missing.message
    far = move(joint_names=names, positions=[100.0, *goal[1:]], speed_scale=1.0, label="")
    assert not far.success and "outside the joint's limits" in far.message
    assert _proxy()(name="start", speed_scale=1.0).success


@pytest.mark.cobot_safety
def test_a_move_toward_the_face_region_is_slowed_to_the_collaborative_speed_cap(stack):
    """The region set live on jog_arm (dynamic_reconfigure, as `dynparam set` does) caps the next named-pose
    move too: the tool's speed stays within the cap the answer names."""
    import re

    import rospy
    from dynamic_reconfigure.client import Client
    from geometry_msgs.msg import PoseStamped

    client = Client("/jog_arm_server", timeout=20)
    poses = Collector("/mujoco_driver/eef_pose", PoseStamped, queue_size=5000)
    try:
        client.update_configuration({"collaborative_region": "face"})
        assert rospy.get_param("/jog_arm_server/collaborative_region") == "face"
        poses.wait_for(1)
        answer = _proxy()(name="home", speed_scale=1.0)
        assert answer.success, answer.message
        found = re.search(r"speed cap \(([0-9.]+) m/s at the tip toward the face", answer.message)
        assert found, answer.message
        cap = float(found.group(1))
        msgs = [m for _, m in poses.timed()]
        tips = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in msgs])
        stamps = np.array([m.header.stamp.to_sec() for m in msgs])  # simulated time
        # Mean speed over 50 ms windows of simulated time: a single pose step's stamp can be off by a
        # simulation step on a busy machine, which a 2 ms difference turns into a false peak.
        later = np.searchsorted(stamps, stamps + 0.05)
        inside = later < len(stamps)
        first, last = np.flatnonzero(inside), later[inside]
        speed = np.linalg.norm(tips[last] - tips[first], axis=1) / (stamps[last] - stamps[first])
        print(f"\ncap {cap} m/s, tool speed peak (50 ms mean) {speed.max():.3f} m/s; {answer.message}")
        # eef_pose is the tool tip, jog_arm's ee_frame_name too; the servos' tracking adds a few percent.
        assert 0.5 * cap < speed.max() <= 1.1 * cap
    finally:
        client.update_configuration({"collaborative_region": "hand"})
        poses.close()
        back = _proxy()(name="start", speed_scale=1.0)
        assert back.success, back.message
