"""key_to_twist: the ROS adapter between a terminal (`terminal`), the teleop logic (`teleop`) and topics."""

from __future__ import annotations

import sys
import threading
import time
from typing import TextIO

import rospy
from compliant_common.ros_master import MasterWatch
from geometry_msgs.msg import TwistStamped

from keyboard_publisher.keymap import Action, key_code, render_help, render_speeds
from keyboard_publisher.msg import KeyEvent
from keyboard_publisher.teleop import ZERO, TeleopSettings, TeleopSettingsError, TeleopState, Twist6
from keyboard_publisher.terminal import KeyReader, RawTerminal, StopSignals, TerminalError

__all__ = ["KeyToTwist", "main"]

NO_TTY_MESSAGE = (
    "key_to_twist: standard input is not a terminal, so no keys can be read. Run it in a terminal "
    "(rosrun keyboard_publisher key_to_twist), or from roslaunch with launch_prefix:='xterm -e'."
)

# After a final zero on exit, give the publisher's queue thread this long to send it before shutdown.
EXIT_FLUSH = 0.1


class KeyToTwist:
    """Publishes the teleop twist at a steady rate and every key as a KeyEvent.

    Args:
        settings: validated parameters.
        out: where the key map and speed changes are printed (the terminal).
    """

    def __init__(self, settings: TeleopSettings, out: TextIO) -> None:
        self._settings = settings
        self._state = TeleopState(settings)
        self._out = out
        self._twist_pub = rospy.Publisher(settings.topic, TwistStamped, queue_size=10)
        self._key_pub = rospy.Publisher(settings.key_event_topic, KeyEvent, queue_size=100)
        self._twist = TwistStamped()
        self._twist.header.frame_id = settings.frame_id
        self._event = KeyEvent()

    def run(self, reader: KeyReader, stop: threading.Event) -> int:
        """Reads keys and publishes until a quit key, a stop signal or ROS shutdown.

        Returns:
            The process exit code (0).
        """
        s = self._settings
        period = 1.0 / s.rate
        self._print(render_help(self._state.linear_speed, self._state.angular_speed, s.max_linear_speed,
                                s.max_angular_speed, s.key_timeout, s.speed_step))
        next_tick = time.monotonic()
        try:
            while not stop.is_set() and not rospy.is_shutdown():
                keys = reader.read(next_tick - time.monotonic())
                now = time.monotonic()
                for key in keys:
                    if not self._on_key(key, now):
                        return 0
                if now >= next_tick:
                    released = self._state.release(now)
                    if released is not None:
                        self._publish_key(released, pressed=False)
                    self._publish(self._state.tick(now))
                    next_tick += period
                    if next_tick < now:  # fell behind (slow terminal or machine): resynchronise, no burst
                        next_tick = now + period
        except TerminalError as err:
            rospy.logwarn(f"key_to_twist: {err}; stopping")
        finally:
            self._stop_on_exit()
        return 0

    def _on_key(self, key: str, now: float) -> bool:
        """Handles one key; False when it asks to quit."""
        result = self._state.press(key, now)
        if result.released is not None:
            self._publish_key(result.released, pressed=False)
        if result.binding is not None and result.binding.action is Action.QUIT:
            return False
        self._publish_key(key, pressed=True)
        if result.speeds_changed:
            s = self._settings
            self._print(render_speeds(self._state.linear_speed, self._state.angular_speed, s.max_linear_speed,
                                      s.max_angular_speed))
        if result.publish_now:
            self._publish(self._state.tick(now))
        return True

    def _publish(self, twist: Twist6 | None) -> None:
        if twist is None:
            return
        msg = self._twist
        msg.header.stamp = rospy.Time.now()
        lin, ang = msg.twist.linear, msg.twist.angular
        lin.x, lin.y, lin.z, ang.x, ang.y, ang.z = twist
        self._twist_pub.publish(msg)

    def _publish_key(self, key: str, pressed: bool) -> None:
        self._event.pressed = pressed
        self._event.char = key if len(key) == 1 else ""
        self._event.keyCode = key_code(key)
        self._key_pub.publish(self._event)

    def _stop_on_exit(self) -> None:
        """Leaving while moving (or while stop zeros are due) sends zero first: best effort."""
        now = time.monotonic()
        due = self._state.command(now) != ZERO or self._state.tick(now) is not None
        if due and not rospy.is_shutdown():
            self._publish(ZERO)
            time.sleep(EXIT_FLUSH)

    def _print(self, text: str) -> None:
        self._out.write(text + "\n")
        self._out.flush()


def main(argv: list[str] | None = None) -> int:
    """Entry point of `rosrun keyboard_publisher key_to_twist`; returns the exit code."""
    stdin = sys.stdin
    if stdin is None or not stdin.isatty():
        sys.stderr.write(NO_TTY_MESSAGE + "\n")
        return 2
    rospy.init_node("key_to_twist", argv=argv, disable_signals=True)  # signals are ours (StopSignals)
    try:
        settings, warnings = TeleopSettings.from_params(rospy.get_param("~", {}))
    except TeleopSettingsError as err:
        rospy.logfatal(f"key_to_twist: {err}")
        return 2
    for warning in warnings:
        rospy.logwarn(f"key_to_twist: {warning}")
    node = KeyToTwist(settings, sys.stdout)
    # Twists keep flowing on existing connections while the master is away; a new one learns of us again.
    MasterWatch(lambda reason: rospy.logwarn(f"key_to_twist: {reason}"), lambda: None, params=["~"])
    fd = stdin.fileno()
    with StopSignals() as signals, RawTerminal(fd):
        code = node.run(KeyReader(fd), signals.event)
    rospy.signal_shutdown("key_to_twist finished")
    return code
