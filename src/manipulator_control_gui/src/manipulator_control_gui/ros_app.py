"""Standalone entry point: `rosrun manipulator_control_gui manipulator_control_gui`."""

from __future__ import annotations

import signal
import sys
from collections.abc import Sequence

__all__ = ["create_widget", "main"]


def create_widget(parent=None):
    """Builds the panel from the node's private parameters (rospy must be initialised).

    Parameters: `manipulator_control_gui.params` (all private; see README). An unknown key or a bad value
    raises ValueError naming it.
    """
    import rospy

    from manipulator_control_gui.form_config import load_config
    from manipulator_control_gui.params import load_settings
    from manipulator_control_gui.ros_client import RosNames
    from manipulator_control_gui.widget import ControlWidget

    settings = load_settings(rospy.get_param("~", {}))
    config = load_config(settings.config or None)
    names = RosNames.from_settings(settings)
    return ControlWidget(config, names, retry_period=settings.retry_period, parent=parent)


def main(argv: Sequence[str] | None = None) -> int:
    """Starts the ROS node and the window; returns the exit code."""
    import rospy
    from python_qt_binding.QtCore import QTimer
    from python_qt_binding.QtWidgets import QApplication

    argv = list(sys.argv if argv is None else argv)
    app = QApplication(argv)
    # Ctrl-C quits, also during start-up: the quit is queued, so it takes effect once the event loop runs.
    # The idle timer lets Python see the signal while Qt's loop runs.
    signal.signal(signal.SIGINT, lambda *_: QTimer.singleShot(0, app.quit))
    rospy.init_node("manipulator_control_gui", argv=argv, disable_signals=True)
    widget = create_widget()
    widget.show()
    tick = QTimer()
    tick.timeout.connect(lambda: None)
    tick.start(200)
    code = app.exec_()
    widget.shutdown()
    rospy.signal_shutdown("window closed")
    return code
