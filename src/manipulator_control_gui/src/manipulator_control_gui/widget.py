"""The Qt panel: six axis rows (law and its fields, live readout), Apply/Stop/Tare/Reset, presets.

Service calls run in worker threads (ros_client) and ROS callbacks come in on rospy threads; both reach the
widget only through Qt signals, so every widget update happens on the UI thread and the UI never waits on ROS.
The rows are built in code from config/gui.yaml (six identical rows), not from a .ui file.
"""

from __future__ import annotations

import time
from typing import Any

from python_qt_binding.QtCore import QObject, Qt, QTimer, Signal
from python_qt_binding.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from manipulator_control_gui.form import (
    EXCEEDED_ACTIONS,
    AxisForm,
    Form,
    FormError,
    build_laws_request,
    build_request,
    describe_response,
    law_form,
    preset_form,
    summarize_form,
)
from manipulator_control_gui.form_config import AXES, AXIS_LABELS, FIELDS, LAW_FIELDS, LAWS, GuiConfig
from manipulator_control_gui.readout import readout_from_status, refusal_in_status
from manipulator_control_gui.ros_client import Availability, CallResult, ContactControlClient, RosNames
from manipulator_control_gui.task_box import TaskBox
from manipulator_control_gui.teach_box import TeachBox

__all__ = ["ControlWidget"]

_OK_STYLE = "color: #1b6e20;"
_ERROR_STYLE = "color: #b00020;"
_BUSY_STYLE = "color: #555555;"
_READOUT_COLUMNS = ("force", "velocity", "travel", "end")
_READOUT_HEADERS = ("F / T", "velocity", "travel", "end condition")
_LAW_TIPS = {
    "none": "The axis does not move.",
    "follower": "V = F / b: the axis follows the force.",
    "spring": "V = F / b - k d: pushed away, the axis returns to where the law was set.",
    "compliant_move": "V = V_desired + F / b: moves at V_desired; contact slows it; ends at a limit.",
}


class _Bridge(QObject):
    """Carries results from ROS threads to the UI thread (queued connections).

    It has no Qt parent, so it is never deleted with the widget while a ROS thread emits on it (a status
    callback or a service answer can still run after `shutdown`): emitting on a QObject whose C++ side is
    being destroyed crashed the process (segfaults in the GUI tests, rarely, on a busy machine). `close`
    disconnects it; later results go nowhere."""

    status = Signal(object)
    availability = Signal(object)
    answer = Signal(str, object)
    task = Signal(str, object)  # ("goal" | "feedback" | "result", the action's message part)

    def __init__(self) -> None:
        super().__init__()
        self._closed = False

    def send(self, signal_name: str, *args: Any) -> None:
        """Emits from any thread; after `close`, drops the result."""
        if self._closed:
            return
        try:
            getattr(self, signal_name).emit(*args)
        except RuntimeError:  # the interpreter is shutting down and took the C++ object with it
            pass

    def close(self) -> None:
        """No more deliveries: the widget is going away."""
        self._closed = True
        for signal in (self.status, self.availability, self.answer, self.task):
            try:
                signal.disconnect()
            except TypeError:  # nothing connected
                pass


class _AxisRow:
    """The widgets of one axis."""

    def __init__(self, axis: str, config: GuiConfig, parent: QWidget) -> None:
        self.axis = axis
        self.law_combo = QComboBox(parent)
        self.law_combo.setObjectName(f"law_{axis}")
        for law in LAWS:
            self.law_combo.addItem(config.law_labels[law], law)
            self.law_combo.setItemData(self.law_combo.count() - 1, _LAW_TIPS[law], Qt.ToolTipRole)
        self.spins: dict[str, QDoubleSpinBox] = {}
        for field in FIELDS:
            spec = config.spec(field, axis)
            spin = QDoubleSpinBox(parent)
            spin.setObjectName(f"{field}_{axis}")
            spin.setDecimals(spec.decimals)
            spin.setRange(spec.minimum, spec.maximum)
            spin.setSingleStep(spec.step)
            spin.setSuffix(f" {spec.unit}")
            spin.setToolTip(f"{spec.label} [{spec.unit}], {spec.minimum:g} to {spec.maximum:g}")
            self.spins[field] = spin
        self.readout = {name: QLabel("–", parent) for name in _READOUT_COLUMNS}
        for name, label in self.readout.items():
            label.setObjectName(f"readout_{name}_{axis}")
            label.setAlignment(
                Qt.AlignRight | Qt.AlignVCenter if name != "end" else Qt.AlignLeft | Qt.AlignVCenter
            )

    @property
    def law(self) -> str:
        return str(self.law_combo.currentData())

    def show_fields(self) -> None:
        used = LAW_FIELDS[self.law]
        for field, spin in self.spins.items():
            spin.setVisible(field in used)
            spin.setEnabled(field in used)

    def set_row(self, row: AxisForm) -> None:
        self.law_combo.setCurrentIndex(self.law_combo.findData(row.law))
        for field, spin in self.spins.items():
            spin.setValue(getattr(row, field))
        self.show_fields()

    def row(self) -> AxisForm:
        return AxisForm(self.law, **{field: spin.value() for field, spin in self.spins.items()})


class ControlWidget(QWidget):
    """The manipulator control panel.

    Args:
        config: the form description (config/gui.yaml).
        names: contact_control's service and topic names.
        retry_period: seconds between checks that the services exist.
        status_timeout: a status older than this [s] is shown as missing.
        parent: Qt parent.
    """

    def __init__(
        self,
        config: GuiConfig,
        names: RosNames,
        retry_period: float = 1.0,
        status_timeout: float = 2.0,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("ManipulatorControlWidget")
        self.setWindowTitle("Manipulator control")
        self.config = config
        self._retry_period = retry_period
        self._status_timeout = status_timeout
        self._last_status_time: float | None = None
        self._filling = False
        self._awaiting_reason = False  # a refusal came back; its reason follows on the status topic
        self._laws_service = False  # contact_control offers ConfigureLaws (answers with the reason)
        self._bridge = _Bridge()  # no parent: see _Bridge
        self._bridge.status.connect(self._show_status)
        self._bridge.availability.connect(self._show_availability)
        self._bridge.answer.connect(self._show_call_result)
        self._build()
        self.client = ContactControlClient(
            names,
            lambda msg: self._bridge.send("status", msg),
            lambda availability: self._bridge.send("availability", availability),
            retry_period,
        )
        self.teach_box = TeachBox(
            self.client, lambda which, result: self._bridge.send("answer", which, result), self
        )
        self._layout.insertWidget(self._layout.indexOf(self.answer_label), self.teach_box)
        self.task_box = TaskBox(self.client.cancel_task, self)
        self._layout.insertWidget(self._layout.indexOf(self.answer_label), self.task_box)
        self._bridge.task.connect(self._show_task)
        self.client.follow_tasks(lambda goal: self._bridge.send("task", "goal", goal),
                                 lambda feedback: self._bridge.send("task", "feedback", feedback),
                                 lambda result: self._bridge.send("task", "result", result))
        self._status_timer = QTimer(self)
        self._status_timer.timeout.connect(self._check_status_age)
        self._status_timer.start(250)
        self.client.start()

    # ---- construction --------------------------------------------------------------------------------------
    def _build(self) -> None:
        layout = self._layout = QVBoxLayout(self)
        self.connection_label = QLabel("Looking for contact_control…", self)
        self.connection_label.setObjectName("connection_label")
        self.connection_label.setWordWrap(True)
        layout.addWidget(self.connection_label)

        preset_line = QHBoxLayout()
        preset_line.addWidget(QLabel("Preset:", self))
        self.preset_combo = QComboBox(self)
        self.preset_combo.setObjectName("preset_combo")
        self.preset_combo.addItem("(choose a thesis demo)", "")
        for name, preset in self.config.presets.items():
            self.preset_combo.addItem(preset.label, name)
        self.preset_combo.activated.connect(self._load_preset_from_combo)
        preset_line.addWidget(self.preset_combo)
        preset_line.addStretch(1)
        layout.addLayout(preset_line)

        laws_box = QGroupBox("Contact law per axis (control frame)", self)
        grid = QGridLayout(laws_box)
        headers = ["axis", "law"] + [self.config.spec(f, "x").label for f in FIELDS] + list(_READOUT_HEADERS)
        for column, text in enumerate(headers):
            header = QLabel(f"<b>{text}</b>", laws_box)
            grid.addWidget(header, 0, column)
        self.rows: dict[str, _AxisRow] = {}
        for r, axis in enumerate(AXES, start=1):
            row = _AxisRow(axis, self.config, laws_box)
            grid.addWidget(QLabel(f"<b>{AXIS_LABELS[axis]}</b>", laws_box), r, 0)
            grid.addWidget(row.law_combo, r, 1)
            for c, field in enumerate(FIELDS, start=2):
                grid.addWidget(row.spins[field], r, c)
            for c, name in enumerate(_READOUT_COLUMNS, start=2 + len(FIELDS)):
                grid.addWidget(row.readout[name], r, c)
            row.law_combo.currentIndexChanged.connect(lambda _i, a=axis: self._law_changed(a))
            row.show_fields()
            self.rows[axis] = row
        limits_line = QHBoxLayout()
        limits_line.addWidget(QLabel("On max force/torque:", laws_box))
        self.action_combo = QComboBox(laws_box)
        self.action_combo.setObjectName("exceeded_action_combo")
        for action, (_code, text) in EXCEEDED_ACTIONS.items():
            self.action_combo.addItem(text, action)
        self.action_combo.setToolTip(
            "What the axes with a max force/torque do when it is reached (exceeded_action)"
        )
        limits_line.addWidget(self.action_combo)
        path_note = "On max path deviation: the whole move ends. 0 means no limit."
        limits_line.addWidget(QLabel(path_note, laws_box))
        limits_line.addStretch(1)
        grid.addLayout(limits_line, len(AXES) + 1, 0, 1, len(headers))
        layout.addWidget(laws_box)

        buttons = QHBoxLayout()
        self.apply_button = QPushButton("Apply", self)
        self.apply_button.setToolTip(
            "Send all six axes in one request (ConfigureLaws when offered, else ConfigureForceControl)"
        )
        self.stop_button = QPushButton("Stop", self)
        self.stop_button.setToolTip("End the move: every axis holds still")
        self.tare_button = QPushButton("Tare", self)
        self.tare_button.setToolTip("Zero the force/torque sensor (nothing should touch the tool)")
        self.reset_button = QPushButton("Reset", self)
        self.reset_button.setToolTip("Clear a latched safety stop")
        self.recover_button = QPushButton("Recover", self)
        self.recover_button.setToolTip("After the robot stopped by itself (a protective stop, a reflex): run "
                                       "the driver's recovery and take commands again from where it is held")
        self.guide_button = QPushButton("Guide", self)
        self.guide_button.setCheckable(True)
        self.guide_button.setToolTip("Hand-guiding: the arm follows a push on every axis (the tool's weight "
                                     "compensated); press again to stop, the arm comes to rest")
        for button, name in (
            (self.apply_button, "apply"),
            (self.stop_button, "stop"),
            (self.tare_button, "tare"),
            (self.reset_button, "reset"),
            (self.recover_button, "recover"),
            (self.guide_button, "guide"),
        ):
            button.setObjectName(f"{name}_button")
            buttons.addWidget(button)
        buttons.addStretch(1)
        self.apply_button.clicked.connect(self.apply)
        self.stop_button.clicked.connect(lambda: self._trigger("stop"))
        self.tare_button.clicked.connect(lambda: self._trigger("tare"))
        self.reset_button.clicked.connect(lambda: self._trigger("reset"))
        self.recover_button.clicked.connect(lambda: self._trigger("recover"))
        self.guide_button.clicked.connect(self._guide)
        layout.addLayout(buttons)

        self.answer_label = QLabel("", self)
        self.answer_label.setObjectName("answer_label")
        self.answer_label.setWordWrap(True)
        self.answer_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        layout.addWidget(self.answer_label)

        status_box = QGroupBox("Status", self)
        status = QGridLayout(status_box)
        self.wrench_label = QLabel("–", status_box)
        self.velocity_label = QLabel("–", status_box)
        self.state_label = QLabel("no status received yet", status_box)
        for r, (title, label, name) in enumerate(
            (
                ("Filtered wrench", self.wrench_label, "wrench_label"),
                ("EEF velocity", self.velocity_label, "velocity_label"),
                ("State", self.state_label, "state_label"),
            )
        ):
            label.setObjectName(name)
            status.addWidget(QLabel(title + ":", status_box), r, 0)
            status.addWidget(label, r, 1)
        status.setColumnStretch(1, 1)
        layout.addWidget(status_box)
        layout.addStretch(1)

    # ---- the form ------------------------------------------------------------------------------------------
    def form(self) -> Form:
        """The form as currently filled in."""
        return {axis: row.row() for axis, row in self.rows.items()}

    @property
    def exceeded_action(self) -> str:
        """The chosen action on max force/torque (a key of form.EXCEEDED_ACTIONS)."""
        return str(self.action_combo.currentData())

    def set_exceeded_action(self, action: str) -> None:
        """Chooses the action on max force/torque (does not send anything)."""
        self.action_combo.setCurrentIndex(self.action_combo.findData(action))

    def set_form(self, form: Form) -> None:
        """Fills the form (does not send it)."""
        self._filling = True
        try:
            for axis, row in self.rows.items():
                row.set_row(form[axis])
        finally:
            self._filling = False

    def load_preset(self, name: str) -> None:
        """Fills the form with preset `name` (does not send it)."""
        self.set_form(preset_form(self.config, name))
        index = self.preset_combo.findData(name)
        self.preset_combo.setCurrentIndex(index)
        label = self.config.presets[name].label
        self._answer(f"Loaded preset '{label}'. Press Apply to send it.", _BUSY_STYLE)

    def _load_preset_from_combo(self, index: int) -> None:
        name = self.preset_combo.itemData(index)
        if name:
            self.load_preset(name)

    def _law_changed(self, axis: str) -> None:
        row = self.rows[axis]
        if not self._filling:
            # A law picked by hand starts from its configured values, not from another law's leftovers.
            start = law_form(self.config, axis, row.law)
            for field in LAW_FIELDS[row.law]:
                row.spins[field].setValue(getattr(start, field))
        row.show_fields()

    # ---- actions -------------------------------------------------------------------------------------------
    def apply(self) -> bool:
        """Checks the form and sends it to the configure service (asynchronously).

        Returns:
            True if a request was sent; False if the form was refused (the answer line says why).
        """
        form = self.form()
        use_laws = self._laws_service
        build = build_laws_request if use_laws else build_request
        try:
            request = build(self.config, form, action=self.exceeded_action)
        except FormError as err:
            self._answer(f"Not sent: {err.message}", _ERROR_STYLE)
            if err.axis in self.rows and err.field in self.rows[err.axis].spins:
                self.rows[err.axis].spins[err.field].setFocus()
            return False
        self._awaiting_reason = False
        self._answer(f"Sending: {summarize_form(self.config, form)} …", _BUSY_STYLE)
        send = self.client.configure_laws if use_laws else self.client.configure
        send(request, lambda result: self._bridge.send("answer", "apply", result))
        return True

    def _trigger(self, which: str) -> None:
        self._awaiting_reason = False
        self._answer(f"{which.capitalize()}: waiting for the answer…", _BUSY_STYLE)
        self.client.trigger(which, lambda result: self._bridge.send("answer", which, result))

    def _guide(self, checked: bool) -> None:
        """The Guide toggle: the button shows what ~status says once it arrives, not the click."""
        self._awaiting_reason = False
        self._answer(f"Guide {'on' if checked else 'off'}: waiting for the answer…", _BUSY_STYLE)
        self.client.guide(checked, lambda result: self._bridge.send("answer", "guide", result))

    # ---- results (UI thread) -------------------------------------------------------------------------------
    def _answer(self, text: str, style: str) -> None:
        self.answer_label.setText(text)
        self.answer_label.setStyleSheet(style)

    def _show_call_result(self, which: str, result: CallResult) -> None:
        if not result.delivered:
            self._answer(
                f"Not applied: {result.message}"
                if which == "apply"
                else f"{which.capitalize()} failed: {result.message}",
                _ERROR_STYLE,
            )
            return
        if which == "apply":
            # ConfigureLaws answers with the code and the reason; the original service with neither, and the
            # reason follows on the status topic.
            self._awaiting_reason = not result.success and result.code is None
            text = describe_response(result.success, result.code, "" if result.success else result.message)
        else:
            verdict = "done" if result.success else "refused"
            text = f"{which.capitalize()} {verdict}" + (f": {result.message}" if result.message else ".")
        self._answer(text, _OK_STYLE if result.success else _ERROR_STYLE)

    def _show_availability(self, availability: Availability) -> None:
        retry = f"retrying every {self._retry_period:g} s"
        if not availability.master:
            text, style = f"ROS master not reachable; {retry}.", _ERROR_STYLE
        elif availability.missing:
            text = f"contact_control not available: {', '.join(availability.missing)} missing; {retry}."
            style = _ERROR_STYLE
        else:
            via = f"; laws via {self.client.resolved.laws_service}" if availability.laws else ""
            text, style = (
                f"Connected to contact_control ({self.client.resolved.configure_service}{via}).",
                _OK_STYLE,
            )
        self._laws_service = availability.ok and availability.laws
        self.connection_label.setText(text)
        self.connection_label.setStyleSheet(style)

    def _show_task(self, part: str, message: Any) -> None:
        {"goal": self.task_box.show_goal, "feedback": self.task_box.show_feedback,
         "result": self.task_box.show_result}[part](message)

    def _show_status(self, status: Any) -> None:
        readout = readout_from_status(status)
        if self._awaiting_reason:
            refusal = refusal_in_status(str(status.message))
            if refusal is not None:
                self._awaiting_reason = False
                self._answer(describe_response(False, *refusal), _ERROR_STYLE)
        self._last_status_time = time.monotonic()
        self.wrench_label.setText(readout.wrench)
        self.velocity_label.setText(readout.velocity)
        self.state_label.setText(readout.state)
        self.state_label.setStyleSheet("" if readout.ok else _ERROR_STYLE)
        guiding = bool(getattr(status, "guiding", False))
        if self.guide_button.isChecked() != guiding:
            self.guide_button.setChecked(guiding)
        for axis, row in self.rows.items():
            cells = readout.axes.get(axis)
            for name, label in row.readout.items():
                label.setText(getattr(cells, name) if cells else "–")

    def _check_status_age(self) -> None:
        last = self._last_status_time
        if last is not None and time.monotonic() - last <= self._status_timeout:
            return
        topic = self.client.resolved.status_topic
        self.state_label.setText(f"no status on {topic}" + (" for a while" if last is not None else " yet"))
        self.state_label.setStyleSheet(_BUSY_STYLE)

    def shutdown(self) -> None:
        """Stops the timers and the ROS side; call before the widget goes away."""
        self._status_timer.stop()
        self.client.shutdown()
        self._bridge.close()
