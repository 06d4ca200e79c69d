"""contact_control_node end to end: real launch file, private master, static tf, a replayed bag of wrenches,
the README's `rosservice call`, refusals, NaN data, blocking service and the safety services."""

from __future__ import annotations

import math
import pathlib
import re
import shlex
import subprocess
import threading

import numpy as np
import pytest
import yaml

from contact_control import ContactControl, load_settings

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from cartesian_impedance_msgs.srv import ConfigureForceControl
from compliant_control_msgs.msg import ContactControlStatus
from contact_control.request import empty_request, fill_request
from geometry_msgs.msg import TwistStamped, WrenchStamped
from harness.bags import typestore, write_bag
from harness.launch import run_launch, run_node
from harness.waiting import Collector, wait_until
from std_srvs.srv import Trigger

PKG = pathlib.Path(__file__).resolve().parents[2] / "src" / "contact_control"
NS = "/cc_test"
NODE = f"{NS}/contact_control_node"
WRENCH, TWIST, STATUS = f"{NS}/wrench", f"{NS}/ee_velocity", f"{NODE}/status"

# Static tf: base_link -> tool0 (an arm's flange pointing down), tool0 -> ft_sensor (turned 90 deg, 5 cm out).
TOOL0 = ([0.4, 0.1, 0.5], [1.0, 0.0, 0.0, 0.0])  # xyz, quaternion xyzw: 180 deg about X
SENSOR = ([0.0, 0.0, 0.05], [0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)])  # 90 deg about Z

OVERRIDE = {
    "ft_in_topic": "wrench",
    "velocity_out_topic": "ee_velocity",
    "fixed_frame": "base_link",
    "control_frame": "base_link",
    "velocity_command_frame": "tool0",  # twists go out in the flange frame (Z down): the node rotates them
    "ft_sensor_frame": "ft_sensor",
    "eef_frame": "tool0",
    "tare_on_startup": False,
    # Memoryless output (no filter, no rate limits), so each twist can be matched to its wrench. The limits
    # are per second of receive time: at 1000 m/s^2 two wrenches delivered 25 us apart after a stall gave a
    # 0.025 m/s step the library (2 ms apart) never gives (seed 2026, once); 1e6 binds only below 0.1 us.
    "lp_filter_enabled": False,
    "acceleration_linear": 1e6,
    "deceleration_linear": 1e6,
    "acceleration_angular": 1e6,
    "deceleration_angular": 1e6,
    "wrench_timeout": 0.2,
    "no_data_end_timeout": 30.0,
    "status_rate": 100.0,
}


def pose_matrix(xyz, q) -> np.ndarray:
    x, y, z, w = q
    T = np.eye(4)
    T[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    T[:3, 3] = xyz
    return T


T_BASE_SENSOR = pose_matrix(*TOOL0) @ pose_matrix(*SENSOR)


def sensor_wrench(base_wrench) -> list[float]:
    """A wrench given in base_link (about the sensor origin) as the sensor reports it."""
    R = T_BASE_SENSOR[:3, :3]
    return (R.T @ np.asarray(base_wrench[:3])).tolist() + (R.T @ np.asarray(base_wrench[3:])).tolist()


def readme_command(containing: str = "/configure_cartesian_impedance ") -> str:
    """The first `rosservice call` of the README's executed examples that contains `containing`."""
    text = (PKG / "README.md").read_text()
    blocks = re.findall(r"README example executed by tests.*?```bash\n(.*?)\n```", text, re.S)
    commands = [line for block in blocks for line in block.splitlines() if line.startswith("rosservice call")]
    found = [c for c in commands if containing in c]
    assert found, f"README lost its executed rosservice example with {containing!r}"
    return found[0]


@pytest.fixture(scope="module")
def node(ros_node, tmp_path_factory):
    override = tmp_path_factory.mktemp("cc") / "override.yaml"
    override.write_text(yaml.safe_dump(OVERRIDE))
    settings = load_settings(
        {**yaml.safe_load((PKG / "config" / "contact_control.yaml").read_text()), **OVERRIDE}
    )
    tf_args = [
        [*map(str, TOOL0[0]), *map(str, TOOL0[1]), "base_link", "tool0"],
        [*map(str, SENSOR[0]), *map(str, SENSOR[1]), "tool0", "ft_sensor"],
    ]
    with (
        run_node("tf2_ros", "static_transform_publisher", args=tf_args[0], name="cc_tf_tool0"),
        run_node("tf2_ros", "static_transform_publisher", args=tf_args[1], name="cc_tf_sensor"),
        run_launch(
            "contact_control", "contact_control.launch", args={"ns": NS, "override_config": override}
        ) as h,
    ):
        h.wait_for_service(f"{NS}/configure_cartesian_impedance")
        h.wait_for_service(f"{NODE}/reset")
        h.wait_for_topic(STATUS)
        pub = ros_node.Publisher(WRENCH, WrenchStamped, queue_size=100, tcp_nodelay=True)
        wait_until(lambda: pub.get_num_connections() > 0, 10, "the node to subscribe to the wrench")
        twists = Collector(TWIST, TwistStamped)
        status = Collector(STATUS, ContactControlStatus)
        yield type("Node", (), {"h": h, "pub": pub, "twists": twists, "status": status, "settings": settings})
        twists.close()
        status.close()


def rosservice(command: str) -> str:
    command = command.replace("call /", f"call {NS}/", 1)
    done = subprocess.run(shlex.split(command), capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    return done.stdout


def trigger(name: str):
    return __import__("rospy").ServiceProxy(f"{NODE}/{name}", Trigger)()


def tare(node, base_wrench):
    """Calls ~tare while publishing `base_wrench` (it averages a window of wrenches); its answer."""
    import concurrent.futures

    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        answer = pool.submit(trigger, "tare")
        while True:
            publish(node, base_wrench)
            try:
                return answer.result(timeout=0.005)
            except concurrent.futures.TimeoutError:
                continue


def publish(node, base_wrench, frame="ft_sensor") -> None:
    import rospy

    msg = WrenchStamped()
    msg.header.stamp = rospy.Time.now()
    msg.header.frame_id = frame
    w = sensor_wrench(base_wrench)
    msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z = w[:3]
    msg.wrench.torque.x, msg.wrench.torque.y, msg.wrench.torque.z = w[3:]
    node.pub.publish(msg)


def raw_twist(msg: TwistStamped) -> list[float]:
    assert msg.header.frame_id == "tool0"
    lin, ang = msg.twist.linear, msg.twist.angular
    return [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z]


def twist_of(msg: TwistStamped) -> list[float]:
    """The twist expressed back in base_link (the control frame), where the tests state expectations."""
    R = pose_matrix(*TOOL0)[:3, :3]
    raw = np.asarray(raw_twist(msg))
    return np.concatenate([R @ raw[:3], R @ raw[3:]]).round(12).tolist()


def wait_twist(node, predicate, base_wrench, message, timeout=10.0) -> list[float]:
    """Publishes `base_wrench` repeatedly until a twist satisfies `predicate`; returns that twist."""
    found: list = []

    def check() -> bool:
        publish(node, base_wrench)
        found[:] = [twist_of(m) for m in list(node.twists.msgs)[-3:] if predicate(twist_of(m))]
        return bool(found)

    node.twists.clear()
    wait_until(check, timeout, message)
    return found[-1]


def latest_status(node, predicate, message, timeout=10.0, keep_publishing=None) -> ContactControlStatus:
    """Waits for a ~status satisfying `predicate`, publishing `keep_publishing` (wrench, frame) meanwhile."""

    def seen() -> bool:
        if keep_publishing is not None:
            publish(node, *keep_publishing)
        return any(predicate(s) for s in list(node.status.msgs))

    node.status.clear()
    wait_until(seen, timeout, message)
    return next(s for s in reversed(list(node.status.msgs)) if predicate(s))


@pytest.fixture
def fresh(node):
    """Each test starts with no move and no latched safety."""
    trigger("stop")
    trigger("reset")
    node.twists.clear()
    return node


def test_readme_follower_on_z_matches_the_library_for_a_replayed_bag(fresh, tmp_path):
    node = fresh
    assert "success: True" in rosservice(readme_command())
    # A bag: 0.3 s at rest, a 6 N push up along base Z with some noise and torque, 0.3 s push down, at 100 Hz.
    ts = typestore()
    Wrench, Header, Vector3 = (
        ts.types[n]
        for n in ("geometry_msgs/msg/WrenchStamped", "std_msgs/msg/Header", "geometry_msgs/msg/Wrench")
    )
    V3, Stamp = ts.types["geometry_msgs/msg/Vector3"], ts.types["builtin_interfaces/msg/Time"]
    rng = np.random.default_rng(1)
    base = [[0, 0, 0, 0, 0, 0]] * 30 + [[0.3, -0.2, 6.0, 0.1, 0.0, 0.2]] * 60 + [[0, 0, -4.0, 0, 0, 0]] * 30
    sensor = [sensor_wrench(np.asarray(b) + rng.normal(0, 0.05, 6)) for b in base]
    stamp0 = 1_700_000_000 * 10**9
    messages = []
    for i, w in enumerate(sensor):
        ns = stamp0 + i * 10_000_000
        msg = Wrench(
            header=Header(seq=i, stamp=Stamp(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="ft_sensor"),
            wrench=Vector3(force=V3(x=w[0], y=w[1], z=w[2]), torque=V3(x=w[3], y=w[4], z=w[5])),
        )
        messages.append((WRENCH, "geometry_msgs/msg/WrenchStamped", ns, msg))
    bag = tmp_path / "push.bag"
    write_bag(bag, messages)
    from harness.bags import replay_bag

    node.twists.clear()
    assert replay_bag(bag) == len(sensor)
    wait_until(lambda: len(node.twists.msgs) >= len(sensor) * 0.9, 10, "twists for the replayed wrenches")

    # The library with the node's settings, fed the same wrenches with the same transforms.
    lib = ContactControl(node.settings)
    lib.set_laws(fill_and_validate_follower_z(), pose_matrix(*TOOL0), 0.0)
    expected = [
        lib.update(w, 0.002 * i, T_BASE_SENSOR, None, pose_matrix(*TOOL0)).velocity
        for i, w in enumerate(sensor)
    ]
    got = [twist_of(m) for m in list(node.twists.msgs)]
    got = got[: next((i for i in range(len(got) - 1, -1, -1) if any(got[i])), 0) + 1]  # drop the stale zeros
    j = 0
    # Every moving twist is the library's answer to one wrench, in order (a dropped one is skipped); a
    # zero may also be the node's stale-data hold when the shared machine stalls the replay > 0.1 s.
    for twist in (t for t in got if any(t)):
        while j < len(expected) and twist != pytest.approx(expected[j], abs=1e-9):
            j += 1
        assert j < len(expected), f"twist {twist} is not the library's output for any later wrench"
    assert max(t[2] for t in got) == pytest.approx(0.2, abs=0.01)  # 6 N / b 30, along +Z only
    assert min(t[2] for t in got) == pytest.approx(-4.0 / 30, abs=0.01)
    assert all(t[0] == t[1] == t[3] == t[4] == t[5] == 0.0 for t in got)
    assert min(raw_twist(m)[2] for m in list(node.twists.msgs)) == pytest.approx(-0.2, abs=0.01)  # Z down


def fill_and_validate_follower_z():
    from contact_control.axes import LAW_FOLLOWER
    from contact_control.laws import AxisLaw
    from contact_control.request import validate_request

    laws = [AxisLaw(), AxisLaw(), AxisLaw(LAW_FOLLOWER, damping=30.0), AxisLaw(), AxisLaw(), AxisLaw()]
    return validate_request(fill_request(empty_request(), laws))


def test_bad_request_is_refused_and_the_previous_law_keeps_running(fresh):
    node = fresh
    assert "success: True" in rosservice(readme_command())
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "the follower to follow")
    bad = (
        'rosservice call /configure_cartesian_impedance "{cart_impedance_params: {damping: {translational: '
        '{x: 30.0}}}, direction_control_laws: {x: {type: 2}}}"'
    )  # spring with k = 0
    assert "success: False" in rosservice(bad)
    twist = wait_twist(node, lambda t: t[2] == pytest.approx(-0.2), [0, 0, -6.0, 0, 0, 0], "still following")
    assert twist[0] == 0.0
    status = latest_status(node, lambda s: "refused" in s.message, "the refusal in ~status")
    assert "code -3" in status.message and status.move_active
    assert "X reads cart_impedance_params.stiffness.translational.x; got 0.0" in status.message
    assert status.safety_name == "ok" and status.axes[2].law_name == "follower"
    # The log's warning starts with the reason (the original response has no field for it).
    wait_until(lambda: re.search(r"\[WARN\] \[[\d.]+\]: axis x \(spring\): stiffness", node.h.output()), 10,
               "the refusal reason at the start of a warning")
    assert status.axes[2].end_condition_name == "none" and status.axes[0].law_name == "none"


def test_nan_wrench_gives_zero_twist_and_a_reason_then_resumes(fresh):
    node = fresh
    assert "success: True" in rosservice(readme_command())
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "the follower to follow")
    node.twists.clear()
    node.status.clear()
    wait_twist(node, lambda t: t == [0.0] * 6, [0, 0, math.nan, 0, 0, 0], "a zero twist for a NaN wrench")
    nan = ([0, 0, math.nan, 0, 0, 0], "ft_sensor")
    status = latest_status(
        node, lambda s: s.safety == ContactControlStatus.SAFETY_NAN, "NaN", keep_publishing=nan
    )
    assert "NaN" in status.message and status.move_active
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "following again")


def test_unknown_sensor_frame_gives_zero_twist_and_no_tf_reason(fresh):
    node = fresh
    assert "success: True" in rosservice(readme_command())
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "the follower to follow")

    def zero_for_unknown_frame() -> bool:
        publish(node, [0, 0, 6.0, 0, 0, 0], frame="no_such_frame")
        return any(twist_of(m) == [0.0] * 6 for m in list(node.twists.msgs)[-3:])

    node.twists.clear()
    wait_until(zero_for_unknown_frame, 10, "a zero twist for a wrench in an unknown frame")
    unknown = ([0, 0, 6.0, 0, 0, 0], "no_such_frame")
    status = latest_status(
        node, lambda s: s.safety == ContactControlStatus.SAFETY_NO_TF, "no tf", keep_publishing=unknown
    )
    assert "no_such_frame" in status.message and status.move_active
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "following again")


def test_blocking_service_answers_when_the_move_ends(fresh):
    import rospy

    node = fresh
    call = rospy.ServiceProxy(f"{NS}/configure_cartesian_impedance_blocking", ConfigureForceControl)
    from contact_control.axes import LAW_COMPLIANT_MOVE
    from contact_control.laws import AxisLaw

    move = [AxisLaw()] * 2 + [AxisLaw(LAW_COMPLIANT_MOVE, velocity=-0.05, force_limit=2.0)] + [AxisLaw()] * 3
    for ending, expected in (("contact", True), ("stop", False)):
        answers: list = []
        request = fill_request(empty_request_msg(), move)
        caller = threading.Thread(target=call_into, args=(call, request, answers))
        caller.start()
        wait_twist(node, lambda t: t[2] == pytest.approx(-0.05), [0] * 6, "the compliant move to run")
        assert not answers  # still blocking while the move runs
        if ending == "contact":
            wait_twist(node, lambda t: t == [0.0] * 6, [0, 0, 3.0, 0, 0, 0], "the move to stop on contact")
            status = latest_status(node, lambda s: not s.move_active, "the end in ~status")
            assert status.axes[2].end_condition == 1 and "axis z" in status.message  # FT_VIOLATION
        else:
            assert trigger("stop").message == "move stopped"
        caller.join(10)
        assert answers and answers[0].success is expected


def call_into(service, request, answers: list) -> None:
    answers.append(service(request))


def empty_request_msg():
    from cartesian_impedance_msgs.srv import ConfigureForceControlRequest

    return ConfigureForceControlRequest()


def test_stale_data_gives_zero_twists_from_the_timer(fresh):
    node = fresh
    assert "success: True" in rosservice(readme_command())
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "the follower to follow")
    node.twists.clear()
    status = latest_status(node, lambda s: s.safety == ContactControlStatus.SAFETY_STALE, "SAFETY_STALE")
    assert status.move_active and "no wrench" in status.message
    node.twists.clear()  # twists still in flight from before the silence
    wait_until(lambda: len(node.twists.msgs) > 5, 5, "zero twists while stale")
    assert all(twist_of(m) == [0.0] * 6 for m in list(node.twists.msgs))


def test_global_limit_latches_until_reset_and_tare_zeroes(fresh):
    node = fresh
    assert "success: True" in rosservice(readme_command())
    # Latched on the second wrench in a row over the limit (force_limit_samples): keep sending it.
    status = latest_status(node, lambda s: s.safety == ContactControlStatus.SAFETY_OVER_LIMIT, "OVER_LIMIT",
                           keep_publishing=([0, 0, 40.0, 0, 0, 0], "ft_sensor"))
    wait_twist(node, lambda t: t == [0.0] * 6, [0, 0, 40.0, 0, 0, 0], "zero output over the global limit")
    assert not status.move_active and "reset" in status.message
    assert "success: False" in rosservice(readme_command())  # refused while latched
    status = latest_status(
        node, lambda s: True, "status", keep_publishing=([0, 0, 6.0, 0, 0, 0], "ft_sensor")
    )
    assert status.safety == ContactControlStatus.SAFETY_OVER_LIMIT  # in range again, still latched
    assert trigger("reset").message == "safety latch cleared"
    assert "success: True" in rosservice(readme_command())
    # Tare with 6 N on the sensor: the same reading afterwards is zero force, so the follower stays still.
    wait_reading(node, [0, 0, 6.0, 0, 0, 0], 6.0)
    answer = tare(node, [0, 0, 6.0, 0, 0, 0])
    assert answer.success and "noise floor at rest" in answer.message, answer.message
    wait_twist(node, lambda t: t == [0.0] * 6, [0, 0, 6.0, 0, 0, 0], "no motion after tare")
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 12.0, 0, 0, 0], "6 N above the tare")
    wait_reading(node, [0] * 6, -6.0)  # back to a zero bias for the other tests
    assert tare(node, [0] * 6).success
    wait_reading(node, [0] * 6, 0.0)


def wait_reading(node, base_wrench, force_z) -> None:
    """Publishes `base_wrench` until ~status shows it was processed (its compensated force z)."""

    def seen() -> bool:
        publish(node, base_wrench)
        return any(abs(s.wrench.force.z - force_z) < 1e-6 for s in list(node.status.msgs)[-3:])

    node.status.clear()
    wait_until(seen, 10, f"the node to read force z {force_z}")


def test_bad_configuration_stops_the_node_naming_the_key(ros_node):
    with run_node(
        "contact_control", "contact_control_node", params={"~max_velocity": -1.0}, name="cc_bad_config"
    ) as h:
        h.proc.wait(timeout=30)
        assert h.proc.returncode != 0
        assert "max_velocity" in h.output()


def test_config_file_documents_every_parameter_with_its_default():
    from contact_control.params import PARAMETERS

    data = yaml.safe_load((PKG / "config" / "contact_control.yaml").read_text())
    assert set(PARAMETERS) - set(data) == {"max_angular_velocity"}  # commented out: defaults to max_velocity
    assert load_settings(data) == load_settings({})


def test_a_status_after_stop_says_the_move_ended_before_the_next_wrench(ros_node):
    """~stop answered, the next status says no move, even when no wrench has come since (the cycle that would
    update the last result waits for one): teach refused a replay right after hand-guiding was switched off,
    "a contact move is running", from a status made between the stop and the next wrench."""
    import rospy
    from cartesian_impedance_msgs.srv import ConfigureForceControlRequest

    ns = "/cc_stop_status"
    params = {"~ft_in_topic": "wrench", "~velocity_out_topic": "ee_velocity", "~tare_on_startup": False,
              "~wrench_timeout": 20.0, "~no_data_end_timeout": 30.0, "~eef_frame": "base_link",
              "~status_rate": 50.0}
    with run_node("contact_control", "contact_control_node", args=[f"__ns:={ns}"], params=params) as h:
        h.wait_for_service(f"{ns}/configure_cartesian_impedance")
        pub = ros_node.Publisher(f"{ns}/wrench", WrenchStamped, queue_size=10, tcp_nodelay=True)
        status = Collector(f"{ns}/contact_control_node/status", ContactControlStatus)
        try:
            wait_until(lambda: pub.get_num_connections() > 0, 10, "the node to subscribe to the wrench")
            msg = WrenchStamped()
            msg.header.frame_id = "base_link"

            def one_wrench() -> bool:
                msg.header.stamp = rospy.Time.now()
                pub.publish(msg)
                last = status.last()
                return last is not None and last.safety == 0

            wait_until(one_wrench, 10, "a wrench seen (status safety ok)")
            req = ConfigureForceControlRequest()
            req.direction_control_laws.z.type = 1  # follower
            req.cart_impedance_params.damping.translational.z = 30.0
            configure = rospy.ServiceProxy(f"{ns}/configure_cartesian_impedance", ConfigureForceControl)
            assert configure(req).success
            one_wrench()  # one cycle with the move: no wrench after this one
            wait_until(lambda: (status.last() or ContactControlStatus()).move_active, 10,
                       "the move in the status")
            assert rospy.ServiceProxy(f"{ns}/contact_control_node/stop", Trigger)().success
            stopped = rospy.Time.now()
            wait_until(lambda: (status.last() or ContactControlStatus()).header.stamp > stopped, 10,
                       "a status after the stop")
            after = [m for m in list(status.msgs) if m.header.stamp > stopped]
            assert not any(m.move_active for m in after), "a status after ~stop said the move still ran"
        finally:
            status.close()
            pub.unregister()


def test_queued_publishing_mode_still_answers_each_push_with_a_follower_twist(ros_node):
    """publish_synchronously: false (rospy's sender thread) must behave as the default does."""
    import rospy
    from cartesian_impedance_msgs.srv import ConfigureForceControlRequest

    ns = "/cc_queued"
    params = {
        "~ft_in_topic": "wrench", "~velocity_out_topic": "ee_velocity", "~publish_synchronously": False,
        "~tare_on_startup": False, "~lp_filter_enabled": False, "~wrench_timeout": 0.5,
        "~eef_frame": "base_link",  # no tf here: the torque's reference point must not need one
    }
    with run_node("contact_control", "contact_control_node", args=[f"__ns:={ns}"], params=params) as h:
        h.wait_for_service(f"{ns}/configure_cartesian_impedance")
        pub = ros_node.Publisher(f"{ns}/wrench", WrenchStamped, queue_size=10, tcp_nodelay=True)
        twists = Collector(f"{ns}/ee_velocity", TwistStamped)
        status = Collector(f"{ns}/contact_control_node/status", ContactControlStatus)
        msg = WrenchStamped()
        msg.header.frame_id = "base_link"
        streaming = threading.Event()

        def sensor() -> None:  # streams at 100 Hz from before the law (a law with no data ends in 1 s)
            rate = rospy.Rate(100)
            while not streaming.is_set() and not rospy.is_shutdown():
                msg.header.stamp = rospy.Time.now()
                pub.publish(msg)
                rate.sleep()

        thread = threading.Thread(target=sensor, daemon=True)
        try:
            wait_until(lambda: pub.get_num_connections() > 0, 10, "the node to subscribe to the wrench")
            thread.start()
            wait_until(lambda: (status.last() or ContactControlStatus(safety=3)).safety == 0, 10,
                       "the node to see the streamed wrench (status safety ok)")
            req = ConfigureForceControlRequest()
            req.direction_control_laws.z.type = 1  # follower
            req.cart_impedance_params.damping.translational.z = 30.0
            configure = rospy.ServiceProxy(f"{ns}/configure_cartesian_impedance", ConfigureForceControl)
            assert configure(req).success
            msg.wrench.force.z = -6.0
            try:
                wait_until(lambda: any(m.twist.linear.z < -0.01 for m in list(twists.msgs)), 10,
                           "a downward twist for a downward push")
            except AssertionError as err:
                last = status.last()
                raise AssertionError(f"{err}; status: {last.message if last else 'none'}") from None
            assert all(abs(m.twist.linear.x) < 1e-9 and m.twist.linear.z <= 0.0 for m in list(twists.msgs))
        finally:
            streaming.set()
            if thread.is_alive():
                thread.join(timeout=5)
            status.close()
            twists.close()
            pub.unregister()


def test_thesis_compliant_move_as_typed_approaches_stops_on_contact_and_moves_away(fresh):
    """README: force limit -0.5 N and damping, no desired velocity, exceeded_action move_away."""
    node = fresh
    answer = rosservice(readme_command("move_away: true"))
    assert "success: True" in answer
    # The laws service says which way a move typed without velocity goes.
    answer = rosservice(readme_command("/configure_laws \"{z: {law: 3"))
    assert "success: True" in answer and "z=compliant_move (v -0.01, move_away)" in answer
    down = node.settings.compliant_default_velocity_linear
    wait_twist(node, lambda t: t[2] == pytest.approx(-down), [0] * 6, "the approach at the default velocity")
    # Contact: the table pushes up with 3 N (over the 0.5 N limit): the move ends, Z backs off upward.
    away = node.settings.move_away_velocity_linear
    wait_twist(node, lambda t: t[2] == pytest.approx(away), [0, 0, 3.0, 0, 0, 0], "backing off", timeout=15)
    status = latest_status(node, lambda s: s.reacting, "reacting in ~status",
                           keep_publishing=([0, 0, 3.0, 0, 0, 0], "ft_sensor"))
    z = status.axes[2]
    assert not status.move_active and z.reacting and z.exceeded_action == "move_away"
    assert z.end_condition_name == "force/torque limit" and z.law_name == "compliant_move"
    # Released (0.1 N is below half the limit): it holds, and says so.
    wait_twist(node, lambda t: t == [0.0] * 6, [0, 0, 0.1, 0, 0, 0], "holding once released")
    status = latest_status(node, lambda s: not s.reacting and "moved away" in s.message, "the release",
                           keep_publishing=([0, 0, 0.1, 0, 0, 0], "ft_sensor"))
    assert status.axes[2].end_condition == 1


def test_configure_laws_answers_with_the_reason_and_a_refusal_changes_nothing(fresh):
    import rospy
    from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsRequest

    node = fresh
    answer = rosservice(readme_command("/configure_laws \"{z:"))
    assert "success: True" in answer and "code: 1" in answer and "z=follower" in answer
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "the follower to follow")
    answer = rosservice(readme_command("/configure_laws \"{rx:"))
    assert "success: False" in answer and "code: -4" in answer
    assert "RX reads rx.damping; got 0.0" in answer
    # Nothing changed: Z still follows (the other way now), RX does not move under a torque.
    pushed = [0, 0, -6.0, 6.0, 0, 0]
    twist = wait_twist(node, lambda t: t[2] == pytest.approx(-0.2), pushed, "still following")
    assert twist[3] == 0.0
    # The same through a proxy: an action without a force limit could never act, so it is refused.
    call = rospy.ServiceProxy(f"{NS}/configure_laws", ConfigureLaws)
    req = ConfigureLawsRequest()
    req.x.law, req.x.damping, req.x.exceeded_action = 1, 30.0, 1
    response = call(req)
    assert not response.success and "set x.force_limit > 0" in response.message
    status = latest_status(node, lambda s: "refused" in s.message, "the refusal in ~status")
    assert status.move_active and status.axes[2].law_name == "follower"


def test_wrench_stamped_in_the_future_gives_zero_twist_and_a_reason_then_resumes(fresh):
    """A sensor on another clock (or data from before a backward clock jump) is refused like NaN."""
    import rospy

    node = fresh
    assert "success: True" in rosservice(readme_command())
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "the follower to follow")
    msg = WrenchStamped()
    msg.header.frame_id = "ft_sensor"
    msg.wrench.force.x, msg.wrench.force.y, msg.wrench.force.z = sensor_wrench([0, 0, 6.0, 0, 0, 0])[:3]

    def ahead() -> bool:
        msg.header.stamp = rospy.Time.now() + rospy.Duration(5.0)
        node.pub.publish(msg)
        return any(twist_of(m) == [0.0] * 6 for m in list(node.twists.msgs)[-3:]) and any(
            "ahead" in s.message and s.safety == ContactControlStatus.SAFETY_NAN
            for s in list(node.status.msgs)
        )

    node.twists.clear()
    node.status.clear()
    wait_until(ahead, 10, "a zero twist and the reason for a wrench stamped 5 s ahead")
    assert node.status.last().move_active
    wait_twist(node, lambda t: t[2] == pytest.approx(0.2), [0, 0, 6.0, 0, 0, 0], "following again")


def test_readme_force_tracking_presses_down_until_the_table_pushes_back_with_the_target(fresh):
    """README: force tracking on Z, 10 N pressing down on a table (target_force +10: the table pushes up)."""
    node = fresh
    answer = rosservice(readme_command("law: 4"))
    assert "success: True" in answer
    assert "z=force_tracking (target 10, b 2000, approach 0.01, move_away)" in answer
    approach = node.settings.compliant_default_velocity_linear
    # Free air: down toward the table at the approach speed (no deadband around zero force).
    wait_twist(node, lambda t: t[2] == pytest.approx(-approach), [0] * 6, "the approach, down")
    # Touching with 8 N: still pressing, at (F - F_target less the 0.2 N deadband) / b (slower than
    # min_velocity: no floor here).
    wait_twist(node, lambda t: t[2] == pytest.approx(-1.8 / 2000.0), [0, 0, 8.0, 0, 0, 0], "pressing harder")
    # At the target (within the 0.2 N deadband) it holds; above it, it eases off upward.
    wait_twist(node, lambda t: t[2] == 0.0, [0, 0, 10.1, 0, 0, 0], "holding at the target")
    wait_twist(node, lambda t: t[2] == pytest.approx(2.8 / 2000.0), [0, 0, 13.0, 0, 0, 0], "easing off")
    status = latest_status(node, lambda s: s.move_active, "the move in ~status",
                           keep_publishing=([0, 0, 13.0, 0, 0, 0], "ft_sensor"))
    assert status.axes[2].law_name == "force_tracking" and status.axes[2].exceeded_action == "move_away"
    # The original service has no force tracking: refused, naming the service that has it.
    answer = rosservice(
        'rosservice call /configure_cartesian_impedance "{cart_impedance_params: {damping: {translational: '
        '{z: 2000.0}}}, direction_control_laws: {z: {type: 4}}}"'
    )
    assert "success: False" in answer
    status = latest_status(node, lambda s: "configure_laws" in s.message, "the refusal's reason in ~status",
                           keep_publishing=([0, 0, 13.0, 0, 0, 0], "ft_sensor"))
    assert status.move_active and status.axes[2].law_name == "force_tracking"  # nothing changed
