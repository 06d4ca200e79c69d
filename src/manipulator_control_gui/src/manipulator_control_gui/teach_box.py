"""The panel's Teach box: record a hand-guided program and replay it (teach's program_server), the answers
shown like the other buttons' (see the package README)."""

from __future__ import annotations

from collections.abc import Callable

from python_qt_binding.QtWidgets import QDoubleSpinBox, QGroupBox, QHBoxLayout, QLabel, QLineEdit, QPushButton

from manipulator_control_gui.ros_client import CallResult, ContactControlClient

__all__ = ["TeachBox"]

Answer = Callable[[str, CallResult], None]


class TeachBox(QGroupBox):
    """Program name, Record, Stop recording, Replay (speed, press along Z), Cancel.

    Args:
        client: the panel's ROS client (its calls answer from worker threads).
        answer: called from those threads with (which, result); the panel shows it in the UI thread.
    """

    def __init__(self, client: ContactControlClient, answer: Answer, parent: QGroupBox | None = None) -> None:
        super().__init__("Teach (guide with the Guide button, record, replay)", parent)
        self.setObjectName("teach_box")
        self._client, self._answer = client, answer
        row = QHBoxLayout(self)
        row.addWidget(QLabel("Program", self))
        self.name_edit = QLineEdit("program1", self)
        self.name_edit.setObjectName("program_edit")
        row.addWidget(self.name_edit)
        self.record_button = QPushButton("Record", self)
        self.stop_button = QPushButton("Stop rec.", self)
        self.replay_button = QPushButton("Replay", self)
        self.cancel_button = QPushButton("Cancel", self)
        self.speed_spin = QDoubleSpinBox(self)
        self.speed_spin.setRange(0.1, 4.0)
        self.speed_spin.setSingleStep(0.1)
        self.speed_spin.setValue(1.0)
        self.speed_spin.setSuffix(" x")
        self.speed_spin.setToolTip("replay speed: the recorded speed times this")
        self.press_spin = QDoubleSpinBox(self)
        self.press_spin.setRange(-50.0, 50.0)
        self.press_spin.setSuffix(" N")
        self.press_spin.setToolTip("press along Z with this force while X, Y follow the path (0: none)")
        widgets = ((self.record_button, "record_button"), (self.stop_button, "stop_recording_button"),
                   (self.speed_spin, "speed_spin"), (self.press_spin, "press_spin"),
                   (self.replay_button, "replay_button"), (self.cancel_button, "cancel_replay_button"))
        for widget, name in widgets:
            widget.setObjectName(name)
            if widget is self.press_spin:
                row.addWidget(QLabel("press Z", self))
            row.addWidget(widget)
        self.record_button.clicked.connect(self._record)
        self.stop_button.clicked.connect(self._stop)
        self.replay_button.clicked.connect(self._replay)
        self.cancel_button.clicked.connect(self._client.cancel_replay)

    def _record(self) -> None:
        self._client.record(self.name_edit.text().strip(), lambda r: self._answer("record", r))

    def _stop(self) -> None:
        self._client.stop_recording(lambda r: self._answer("stop recording", r))

    def _replay(self) -> None:
        press = self.press_spin.value()
        name = self.name_edit.text().strip()
        self._client.replay(name, self.speed_spin.value(), "z" if press else "", press,
                            lambda r: self._answer("replay", r))
