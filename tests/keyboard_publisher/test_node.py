"""key_to_twist end to end: the real node on a pseudo-terminal, a private master, the published twists."""

from __future__ import annotations

import os
import signal
import threading
import time
import xmlrpc.client

import pytest
from harness.launch import run_node
from harness.waiting import Collector, wait_until

KeyEvent = pytest.importorskip("keyboard_publisher.msg", reason="build the workspace first").KeyEvent


def test_key_event_is_the_original_message():
    assert KeyEvent._md5sum == "363de715224404dfcba285c1286b8f13"
    assert KeyEvent._type == "keyboard_publisher/KeyEvent"


def twist_values(msg) -> tuple[float, ...]:
    lin, ang = msg.twist.linear, msg.twist.angular
    return (lin.x, lin.y, lin.z, ang.x, ang.y, ang.z)


def is_zero(msg) -> bool:
    return not any(twist_values(msg))


def start_node(pty_run, name: str, params: dict[str, object]):
    # A name per test: private parameters stay on the master after a node exits.
    cmd = ["rosrun", "keyboard_publisher", "key_to_twist", f"__name:={name}"]
    cmd += [f"_{key}:={value}" for key, value in params.items()]
    return pty_run(cmd)


def wait_publishing(node: str, *topics: str, timeout: float = 20.0) -> None:
    """Waits until `node` itself lists an outgoing connection on each topic.

    The subscriber side counts a connection slightly before the publisher adds it, and a message
    published in between is lost; the publisher's own bus info closes that gap.
    """
    master = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])

    def connected() -> bool:
        code, _, uri = master.lookupNode("/pytest", node)
        if code != 1:
            return False
        _, _, bus_info = xmlrpc.client.ServerProxy(uri).getBusInfo("/pytest")
        outgoing = {entry[4] for entry in bus_info if entry[2] == "o"}
        return all(topic in outgoing for topic in topics)

    wait_until(connected, timeout, f"{node} connected to our subscribers on {topics}")


def test_keys_move_stop_and_speed_up_within_bounds_then_ctrl_c_quits(ros_node, pty_run):
    from geometry_msgs.msg import TwistStamped

    # Default topics and frame; a long deadman so every zero seen here comes from a key.
    params = {"key_timeout": 30.0, "max_linear_speed": 0.3, "speed_step": 1.25}
    with start_node(pty_run, "kbd_a", params) as node:
        twists = Collector("/jog_arm_server/delta_jog_cmds", TwistStamped)
        events = Collector("/keyboard_publisher/key_event", KeyEvent)
        try:
            node.wait_output("speed: linear 0.200 m/s (max 0.300)")
            assert "linear x" in node.output() and "Ctrl-C" in node.output()  # the key map is shown
            assert node.is_raw()
            wait_publishing("/kbd_a", "/jog_arm_server/delta_jog_cmds", "/keyboard_publisher/key_event")

            node.write(b"w")
            wait_until(lambda: twists.msgs and twists.msgs[-1].twist.linear.x > 0, 10, "a +x twist")
            first = twists.msgs[-1]
            assert twist_values(first) == pytest.approx((0.2, 0, 0, 0, 0, 0))
            assert first.header.frame_id == ""
            event = events.wait_for(1)[0]
            assert (event.pressed, event.char, event.keyCode) == (True, "w", 119)
            # Published steadily while the command holds, not only on key events.
            count = len(twists.msgs)
            twists.wait_for(count + 10)
            assert all(m.twist.linear.x == pytest.approx(0.2) for m in twists.msgs)

            node.write(b"x")
            wait_until(lambda: is_zero(twists.msgs[-1]), 10, "a zero twist after the stop key")

            node.write(b"ttt")  # 0.2 -> 0.25 -> 0.3125, bounded to 0.3
            node.wait_output("speed: linear 0.250 m/s")
            node.wait_output("speed: linear 0.300 m/s")
            node.write(b"\x1b[A")  # up arrow = +x
            wait_until(lambda: twists.msgs[-1].twist.linear.x > 0, 10, "a +x twist after the arrow key")
            assert twists.msgs[-1].twist.linear.x == pytest.approx(0.3)
            wait_until(lambda: any(e.keyCode == 0xFF52 for e in events.msgs), 10, "the up arrow's KeyEvent")

            node.write(b"\x03")  # Ctrl-C: a key in raw mode
            assert node.wait_exit() == 0
            assert node.mode() == node.initial_mode  # terminal restored
            wait_until(lambda: is_zero(twists.msgs[-1]), 10, "a zero twist when quitting while moving")
        finally:
            twists.close()
            events.close()


def test_deadman_zero_after_key_timeout_and_sigterm_exits_cleanly(ros_node, pty_run):
    from geometry_msgs.msg import TwistStamped

    params = {"topic": "/kbd_b/cmd", "key_event_topic": "/kbd_b/keys", "frame_id": "tool0", "stop_repeats": 3}
    with start_node(pty_run, "kbd_b", params) as node:
        twists = Collector("/kbd_b/cmd", TwistStamped)
        events = Collector("/kbd_b/keys", KeyEvent)
        stop_typing = threading.Event()

        def hold_key() -> None:  # a held key as a terminal delivers it: auto-repeat at ~30 Hz
            while not stop_typing.wait(1 / 30):
                node.write(b"d")

        typist = threading.Thread(target=hold_key, daemon=True)
        try:
            node.wait_output("speed: linear")
            wait_publishing("/kbd_b", "/kbd_b/cmd", "/kbd_b/keys")
            typist.start()
            twists.wait_for(30)
            stop_typing.set()
            typist.join()
            released_at = time.monotonic()

            wait_until(lambda: any(is_zero(m) for m in twists.msgs), 10, "a zero twist after the key timeout")
            first_zero = next(n for n, m in enumerate(twists.msgs) if is_zero(m))
            assert twists.times[first_zero] > released_at  # no stutter while the key was held
            for msg in twists.msgs[:first_zero]:
                assert twist_values(msg) == pytest.approx((0, 0.2, 0, 0, 0, 0))
                assert msg.header.frame_id == "tool0"
            wait_until(lambda: len(twists.msgs) >= first_zero + 3, 10, "three zeros")
            assert all(is_zero(m) for m in twists.msgs[first_zero:])
            wait_until(lambda: any(not e.pressed for e in events.msgs), 10, "the synthesized release event")
            assert [e.char for e in events.msgs if not e.pressed] == ["d"]

            os.killpg(node.proc.pid, signal.SIGTERM)
            assert node.wait_exit() == 0
            assert node.mode() == node.initial_mode
        finally:
            stop_typing.set()
            twists.close()
            events.close()


def test_bad_parameter_stops_the_node_naming_it(ros_node, pty_run):
    with start_node(pty_run, "kbd_c", {"max_linear_speed": 0.1}) as node:  # below the initial 0.2 m/s
        assert node.wait_exit() == 2
        assert "'~linear_speed'" in node.output()
        assert node.mode() == node.initial_mode


def test_without_a_terminal_it_refuses_and_exits_non_zero():
    with run_node("keyboard_publisher", "key_to_twist") as handle:  # stdin is /dev/null
        assert handle.proc.wait(timeout=20) == 2
        assert "standard input is not a terminal" in handle.output()


def test_launch_file_passes_its_args(ros_node, pty_run):
    from geometry_msgs.msg import TwistStamped

    cmd = ["roslaunch", "keyboard_publisher", "keyboard.launch", "topic:=/kbd_d/cmd", "frame_id:=base_link",
           "key_event_topic:=/kbd_d/keys", "linear_speed:=0.1", "rate:=20"]
    with pty_run(cmd) as launch:
        twists = Collector("/kbd_d/cmd", TwistStamped)
        try:
            launch.wait_output("speed: linear 0.100 m/s")
            wait_publishing("/key_to_twist", "/kbd_d/cmd")
            launch.write(b"f")
            wait_until(lambda: twists.msgs and twists.msgs[-1].twist.linear.z < 0, 10, "a -z twist")
            assert twist_values(twists.msgs[-1]) == pytest.approx((0, 0, -0.1, 0, 0, 0))
            assert twists.msgs[-1].header.frame_id == "base_link"
            launch.write(b"\x03")  # quits the required node, which ends the launch
            launch.wait_exit(timeout=30)
            assert launch.mode() == launch.initial_mode
        finally:
            twists.close()
