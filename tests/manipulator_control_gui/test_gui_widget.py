"""The panel against real ROS services on a real master: what a user does and sees.

A stand-in contact_control (rospy services and a status publisher in this process) records what the
panel sends. Set MCG_WRITE_SCREENSHOT=1 to also refresh the README figure (doc/screenshot.png).
"""

import itertools
import os
import pathlib
import threading

import pytest
from cartesian_impedance_msgs.msg import CartesianForceCtrlErrorCodes
from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlResponse
from compliant_control_msgs.msg import AxisState, ContactControlStatus
from compliant_control_msgs.srv import ConfigureLaws, ConfigureLawsResponse, Guide, GuideResponse
from manipulator_control_gui.form_config import AXES, load_config
from manipulator_control_gui.ros_client import RosNames
from std_srvs.srv import Trigger, TriggerResponse

CONFIG = load_config()
DOC_SCREENSHOT = (
    pathlib.Path(__file__).resolve().parents[2] / "src" / "manipulator_control_gui" / "doc" / "screenshot.png"
)
_ids = itertools.count()


class FakeContactControl:
    """Services and status topic shaped like contact_control_node's, recording every call."""

    def __init__(self, rospy, ns: str, success: bool = True, laws: bool = False) -> None:
        self.rospy = rospy
        self.requests: list = []
        self.laws_requests: list = []
        self.triggers: list[str] = []
        self.success = success
        self.gate = threading.Event()
        self.gate.set()
        node = f"{ns}/contact_control_node"
        self.services = [
            rospy.Service(f"{ns}/configure_cartesian_impedance", ConfigureForceControl, self._configure)
        ]
        if laws:  # a contact_control that also offers ConfigureLaws
            self.services.append(rospy.Service(f"{ns}/configure_laws", ConfigureLaws, self._configure_laws))
        for name in ("stop", "tare", "reset"):
            self.services.append(
                rospy.Service(f"{node}/{name}", Trigger, lambda _req, n=name: self._trigger(n))
            )
        self.services.append(rospy.Service(f"{ns}/jog_arm_server/recover", Trigger,
                                           lambda _req: self._trigger("recover")))
        self.guides: list[bool] = []
        self.services.append(rospy.Service(f"{node}/guide", Guide, self._guide))
        self.status = rospy.Publisher(f"{node}/status", ContactControlStatus, queue_size=10)

    def _configure(self, req):
        self.requests.append(req)
        self.gate.wait(30.0)  # a test may hold the answer back to show the window keeps running
        # The reply's error message declares constants only (as the original): no code travels.
        return ConfigureForceControlResponse(success=self.success, error=CartesianForceCtrlErrorCodes())

    def _configure_laws(self, req):
        self.laws_requests.append(req)
        if self.success:
            message = "contact laws set (move 1): z=compliant_move (move_away)"
            return ConfigureLawsResponse(success=True, code=1, message=message)
        reason = "axis z (follower): damping b must be finite and > 0; Z reads z.damping; got 0.0"
        return ConfigureLawsResponse(success=False, code=-4, message=reason)

    def _trigger(self, name: str) -> TriggerResponse:
        self.triggers.append(name)
        return TriggerResponse(success=True, message=f"{name} done by the test service")

    def _guide(self, req) -> GuideResponse:
        self.guides.append(req.enable)
        if req.enable and not self.success:
            return GuideResponse(success=False, code=99999, message="hand-guiding refused: a contact move is "
                                 "running (move 3): z=force_tracking; stop it first (~stop)")
        return GuideResponse(success=True, code=1, message="hand-guiding on (move 4)" if req.enable
                             else "hand-guiding off: the arm comes to rest")

    def close(self) -> None:
        self.gate.set()
        for service in self.services:
            service.shutdown()
        self.status.unregister()


def names_in(ns: str) -> RosNames:
    params = {
        "~contact_control_node": f"{ns}/contact_control_node",
        "~configure_service": f"{ns}/configure_cartesian_impedance",
        "~teach_node": f"{ns}/teach",
        "~recover_service": f"{ns}/jog_arm_server/recover",
        "~task_server": f"{ns}/task_server",
    }
    return RosNames.from_params(lambda key, default: params.get(key, default))


@pytest.fixture
def ns(ros_node) -> str:
    return f"/gui_test_{next(_ids)}"


@pytest.fixture
def fake(ros_node, ns):
    server = FakeContactControl(ros_node, ns)
    yield server
    server.close()


@pytest.fixture
def make_widget(qapp, pump):
    from manipulator_control_gui.widget import ControlWidget

    made = []

    def make(ns: str):
        widget = ControlWidget(CONFIG, names_in(ns), retry_period=0.2)
        widget.show()
        made.append(widget)
        return widget

    yield make
    for widget in made:
        widget.shutdown()
        widget.close()
        widget.deleteLater()
    qapp.processEvents()


def connected(widget) -> bool:
    return widget.connection_label.text().startswith("Connected")


def choose_law(widget, axis: str, law: str) -> None:
    combo = widget.rows[axis].law_combo
    combo.setCurrentIndex(combo.findData(law))


def type_value(spin, text: str) -> None:
    """Types into a spin box as a user would (select all, type, Enter)."""
    from python_qt_binding.QtCore import Qt
    from python_qt_binding.QtTest import QTest

    spin.selectAll()
    QTest.keyClicks(spin, text)
    QTest.keyClick(spin, Qt.Key_Enter)


def click(button) -> None:
    from python_qt_binding.QtCore import Qt
    from python_qt_binding.QtTest import QTest

    QTest.mouseClick(button, Qt.LeftButton)


def test_apply_sends_what_the_user_filled_in(fake, ns, make_widget, pump):
    widget = make_widget(ns)
    pump(lambda: connected(widget), message="the connection line to say connected")
    choose_law(widget, "z", "follower")
    type_value(widget.rows["z"].spins["damping"], "45")
    choose_law(widget, "x", "spring")
    type_value(widget.rows["x"].spins["stiffness"], "50")
    choose_law(widget, "rz", "compliant_move")
    type_value(widget.rows["rz"].spins["velocity"], "-0.1")
    # Only the fields of the chosen law are shown.
    assert widget.rows["z"].spins["damping"].isVisible()
    assert not widget.rows["z"].spins["stiffness"].isVisible()
    assert not widget.rows["z"].spins["velocity"].isVisible()
    assert widget.rows["x"].spins["stiffness"].isVisible()
    assert not any(spin.isVisible() for spin in widget.rows["y"].spins.values())

    click(widget.apply_button)
    pump(lambda: fake.requests, message="the request at the service")
    pump(lambda: widget.answer_label.text().startswith("Applied"), message="the answer line")

    assert len(fake.requests) == 1
    req = fake.requests[0]
    p = req.cart_impedance_params
    laws = req.direction_control_laws
    assert [getattr(laws, a).type for a in AXES] == [2, 0, 1, 0, 0, 3]
    assert p.damping.translational.z == 45.0 and p.damping.translational.x == 30.0
    assert p.stiffness.translational.x == 50.0 and p.stiffness.translational.z == 0.0
    assert p.max_cart_vel.set.angular.z == -0.1 and p.max_cart_vel.set.linear.z == 0.0
    assert p.max_ctrl_force.set.torque.z == 0.5 and p.max_path_deviation.rotation.z == 0.5
    assert p.damping.rotational.z == 30.0
    assert p.max_ctrl_force.exceeded_action.stop  # the default choice
    assert not p.max_ctrl_force.exceeded_action.move_away
    assert "Applied: contact control accepted the laws." == widget.answer_label.text()


def test_a_refusal_is_shown_in_plain_words(ros_node, ns, make_widget, pump):
    server = FakeContactControl(ros_node, ns, success=False)
    try:
        widget = make_widget(ns)
        widget.load_preset("spring_x")
        click(widget.apply_button)
        pump(lambda: widget.answer_label.text().startswith("Refused"), message="the refusal")
        text = widget.answer_label.text()
        assert text.startswith("Refused: contact control did not accept the laws.")
        assert "press Reset" in text and "max_velocity" in text
        assert "color: #b00020" in widget.answer_label.styleSheet()  # shown as an error
        assert len(server.requests) == 1
        # contact_control_node gives the reason on its status topic; the answer line picks it up.
        status = ContactControlStatus(
            message="no laws set; last request refused (code -3): axis x (spring): stiffness k must be > 0"
        )
        pump(lambda: server.status.get_num_connections() > 0, message="the status subscriber")
        server.status.publish(status)
        pump(lambda: "stiffness k must be > 0" in widget.answer_label.text(), message="the reason")
        assert widget.answer_label.text() == (
            "Refused: axis x (spring): stiffness k must be > 0 (error SET_FORCE_STIFFNESS_FAILED, -3)."
        )
    finally:
        server.close()


@pytest.mark.parametrize("success", [True, False])
def test_configure_laws_is_used_when_offered_and_its_reason_shown(ros_node, ns, make_widget, pump, success):
    server = FakeContactControl(ros_node, ns, success=success, laws=True)
    try:
        widget = make_widget(ns)
        pump(lambda: "laws via" in widget.connection_label.text(), message="ConfigureLaws to be found")
        assert f"{ns}/configure_laws" in widget.connection_label.text()
        widget.load_preset("compliant_move_z")
        widget.set_exceeded_action("move_away")
        click(widget.apply_button)
        pump(lambda: server.laws_requests, message="the request at configure_laws")
        word = "Applied" if success else "Refused"
        pump(lambda: widget.answer_label.text().startswith(word), message="the answer line")
        assert not server.requests  # the original service was not called
        z = server.laws_requests[0].z
        assert (z.law, z.force_limit, z.exceeded_action) == (3, 0.5, 1)  # move away on the limited axis
        if not success:  # the reason comes with the answer, no status needed
            assert widget.answer_label.text() == (
                "Refused: axis z (follower): damping b must be finite and > 0; Z reads z.damping; got 0.0 "
                "(error SET_CARTESIAN_CONTROL_FAILED, -4)."
            )
    finally:
        server.close()


def test_an_invalid_form_sends_nothing(fake, ns, make_widget, pump):
    widget = make_widget(ns)
    pump(lambda: connected(widget), message="connected")
    sent = []
    real_configure = widget.client.configure
    widget.client.configure = lambda req, done: (sent.append(req), real_configure(req, done))

    choose_law(widget, "x", "spring")
    type_value(widget.rows["x"].spins["stiffness"], "0")
    click(widget.apply_button)
    assert widget.answer_label.text() == (
        "Not sent: Axis X (spring): stiffness k must be above 0 1/s (with k = 0 nothing pulls the axis back)."
    )
    choose_law(widget, "z", "compliant_move")
    type_value(widget.rows["z"].spins["velocity"], "0")
    choose_law(widget, "x", "none")
    click(widget.apply_button)
    assert "Axis Z (compliant move): desired velocity must not be 0" in widget.answer_label.text()
    assert sent == []

    # Corrected, it goes out, and it is the only request the service ever got.
    type_value(widget.rows["z"].spins["velocity"], "-0.02")
    click(widget.apply_button)
    pump(lambda: widget.answer_label.text().startswith("Applied"), message="the corrected request's answer")
    assert len(sent) == 1 and len(fake.requests) == 1
    assert fake.requests[0].direction_control_laws.x.type == 0
    assert fake.requests[0].cart_impedance_params.max_cart_vel.set.linear.z == -0.02


def test_missing_service_is_reported_and_found_when_it_appears(ros_node, ns, make_widget, pump):
    widget = make_widget(ns)
    pump(lambda: "not available" in widget.connection_label.text(), message="'not available'")
    assert f"{ns}/configure_cartesian_impedance" in widget.connection_label.text()
    assert "retrying every 0.2 s" in widget.connection_label.text()

    widget.load_preset("follower_z")
    click(widget.apply_button)
    pump(lambda: widget.answer_label.text().startswith("Not applied"), message="the failed call's answer")
    assert "is not available" in widget.answer_label.text()

    server = FakeContactControl(ros_node, ns)  # contact_control comes up later
    try:
        pump(lambda: connected(widget), message="the connection line to notice the service")
        click(widget.apply_button)
        pump(lambda: widget.answer_label.text().startswith("Applied"), message="the answer once it is up")
        assert len(server.requests) == 1
    finally:
        server.close()


def test_the_window_keeps_running_while_a_call_is_pending(fake, ns, make_widget, pump):
    from python_qt_binding.QtCore import QTimer

    widget = make_widget(ns)
    pump(lambda: connected(widget), message="connected")
    ticks = []
    timer = QTimer()
    timer.timeout.connect(lambda: ticks.append(1))
    timer.start(10)
    fake.gate.clear()  # the service holds its answer
    try:
        widget.load_preset("hybrid")
        click(widget.apply_button)  # returns at once: the call runs in a worker thread
        assert widget.answer_label.text().startswith("Sending: X compliant move, Z spring")
        pump(lambda: fake.requests and len(ticks) >= 10, message="the event loop to run during the call")
        assert widget.answer_label.text().startswith("Sending")  # still waiting, and not frozen:
        click(widget.stop_button)  # Stop still works while Apply waits
        pump(lambda: fake.triggers == ["stop"], message="the stop call")
        pump(lambda: widget.answer_label.text().startswith("Stop done"), message="stop's answer")
    finally:
        fake.gate.set()
        timer.stop()
    pump(lambda: widget.answer_label.text().startswith("Applied"), message="the held answer")


def test_stop_tare_reset_recover_call_their_services(fake, ns, make_widget, pump):
    widget = make_widget(ns)
    for button, name in (
        (widget.stop_button, "stop"),
        (widget.tare_button, "tare"),
        (widget.reset_button, "reset"),
        (widget.recover_button, "recover"),
    ):
        click(button)
        pump(lambda n=name: fake.triggers[-1:] == [n], message=f"the {name} call")
        pump(
            lambda n=name: (
                widget.answer_label.text() == f"{n.capitalize()} done: {n} done by the test service"
            ),
            message=f"{name}'s answer",
        )
    assert fake.triggers == ["stop", "tare", "reset", "recover"]
    assert not fake.requests


def publish_status(fake, pump, widget) -> ContactControlStatus:
    status = ContactControlStatus(move_active=True, safety=ContactControlStatus.SAFETY_OK, message="")
    status.wrench.force.x, status.wrench.force.z = 0.21, -3.4
    status.velocity.linear.x, status.velocity.linear.z = 0.02, -0.011
    laws = {"x": 3, "z": 2}
    for axis in AXES:
        status.axes.append(AxisState(axis=axis, law=laws.get(axis, 0)))
    status.axes[0].force, status.axes[0].velocity, status.axes[0].travel = 0.21, 0.02, 0.134
    status.axes[2].force, status.axes[2].velocity, status.axes[2].travel = -3.4, -0.011, -0.012
    pump(lambda: fake.status.get_num_connections() > 0, message="the panel to subscribe to the status")
    fake.status.publish(status)
    pump(lambda: "-3.40" in widget.wrench_label.text(), message="the wrench readout")
    return status


def test_live_readout_follows_the_status_topic(fake, ns, make_widget, pump):
    widget = make_widget(ns)
    publish_status(fake, pump, widget)
    assert widget.wrench_label.text() == "F [+0.21 +0.00 -3.40] N   T [+0.00 +0.00 +0.00] N·m"
    assert widget.velocity_label.text().startswith("v [+0.020 +0.000 -0.011] m/s")
    assert widget.state_label.text() == "move running · safety ok"
    assert widget.rows["x"].readout["travel"].text() == "+0.134 m"
    assert widget.rows["x"].readout["end"].text() == "running"
    assert widget.rows["z"].readout["force"].text() == "-3.40 N"

    ended = ContactControlStatus(
        move_active=False, safety=ContactControlStatus.SAFETY_OK, message="x: max travel"
    )
    ended.axes = [AxisState(axis=a) for a in AXES]
    ended.axes[0].end_condition = AxisState.MAX_TRAVEL
    fake.status.publish(ended)
    pump(
        lambda: widget.rows["x"].readout["end"].text() == "ended: max path deviation",
        message="the end condition",
    )
    assert widget.state_label.text() == "no move · safety ok · x: max travel"


def test_preset_selector_fills_the_form_without_sending(fake, ns, make_widget, pump):
    widget = make_widget(ns)
    combo = widget.preset_combo
    index = combo.findData("hybrid")
    combo.setCurrentIndex(index)
    combo.activated.emit(index)  # what a user's pick emits
    form = widget.form()
    assert (form["x"].law, form["x"].max_deviation, form["x"].velocity) == ("compliant_move", 0.3, 0.02)
    assert (form["z"].law, form["z"].stiffness) == ("spring", 100.0)
    assert widget.rows["x"].spins["max_deviation"].isVisible()
    assert "Press Apply" in widget.answer_label.text()
    assert not fake.requests


@pytest.fixture
def robot_fake(ros_node):
    server = FakeContactControl(ros_node, "/robot")  # a namespace that reads naturally in the README figure
    yield server
    server.close()


def test_screenshot(robot_fake, make_widget, pump, tmp_path):
    from python_qt_binding.QtGui import QImage

    widget = make_widget("/robot")
    pump(lambda: connected(widget), message="connected")
    widget.load_preset("hybrid")
    click(widget.apply_button)
    pump(lambda: widget.answer_label.text().startswith("Applied"), message="applied")
    publish_status(robot_fake, pump, widget)
    widget.resize(widget.sizeHint())
    path = tmp_path / "panel.png"
    assert widget.grab().save(str(path))
    image = QImage(str(path))
    assert image.width() >= 800 and image.height() >= 300
    if os.environ.get("MCG_WRITE_SCREENSHOT"):
        DOC_SCREENSHOT.parent.mkdir(exist_ok=True)
        assert widget.grab().save(str(DOC_SCREENSHOT), "PNG", 9)
        assert DOC_SCREENSHOT.stat().st_size < 300_000


class FakeContext:
    """What rqt hands a plugin."""

    def __init__(self) -> None:
        self.widgets = []

    def serial_number(self) -> int:
        return 2

    def add_widget(self, widget) -> None:
        self.widgets.append(widget)


class FakeSettings:
    def __init__(self) -> None:
        self.data = {}

    def set_value(self, key, value) -> None:
        self.data[key] = value

    def value(self, key, default=None):
        return self.data.get(key, default)


def test_rqt_plugin_builds_the_panel_and_keeps_the_form(qapp, ros_node):
    from manipulator_control_gui.plugin import ManipulatorControlPlugin

    context = FakeContext()
    plugin = ManipulatorControlPlugin(context)
    try:
        assert context.widgets == [plugin.widget]
        assert plugin.widget.windowTitle() == "Manipulator control (2)"
        assert plugin.widget.client.resolved.status_topic == "/contact_control_node/status"
        plugin.widget.load_preset("spring_x")
        plugin.widget.set_exceeded_action("gravity_compensation")
        settings = FakeSettings()
        plugin.save_settings(FakeSettings(), settings)
        plugin.widget.load_preset("follower_z")
        plugin.widget.set_exceeded_action("stop")
        plugin.restore_settings(FakeSettings(), settings)
        assert plugin.widget.form()["x"].law == "spring" and plugin.widget.form()["z"].law == "none"
        assert plugin.widget.exceeded_action == "gravity_compensation"
        settings.set_value("form", "{not json")
        plugin.restore_settings(FakeSettings(), settings)  # ignored, form unchanged
        assert plugin.widget.form()["x"].law == "spring"
    finally:
        plugin.shutdown_plugin()
        plugin.widget.deleteLater()


def test_guide_toggle_calls_the_service_shows_the_answer_and_follows_the_status(fake, ns, make_widget, pump):
    widget = make_widget(ns)
    click(widget.guide_button)
    pump(lambda: fake.guides == [True], message="the guide call")
    pump(lambda: widget.answer_label.text() == "Guide done: hand-guiding on (move 4)", message="the answer")
    status = ContactControlStatus(move_active=True, guiding=True, safety=ContactControlStatus.SAFETY_OK)
    status.axes = [AxisState(axis=axis, law=1) for axis in AXES]
    fake.status.publish(status)
    pump(lambda: widget.guide_button.isChecked(), message="the toggle to show guiding")
    click(widget.guide_button)
    pump(lambda: fake.guides == [True, False], message="the off call")
    status.guiding = status.move_active = False
    for _ in range(3):  # the readout follows the status, whatever the click showed
        fake.status.publish(status)
    pump(lambda: not widget.guide_button.isChecked() and "off" in widget.answer_label.text(),
         message="the toggle to show not guiding")


def test_guide_refused_shows_the_reason(ns, make_widget, pump, ros_node):
    refusing = FakeContactControl(ros_node, ns, success=False)
    try:
        widget = make_widget(ns)
        click(widget.guide_button)
        pump(lambda: "contact move is running" in widget.answer_label.text(), message="the reason")
        assert widget.answer_label.text().startswith("Guide refused: hand-guiding refused")
    finally:
        refusing.close()


class FakeTeach:
    """teach's program_server shaped services and replay action, recording what the panel sends."""

    def __init__(self, rospy, ns: str) -> None:
        import actionlib
        from compliant_control_msgs.msg import ReplayProgramAction, ReplayProgramResult
        from compliant_control_msgs.srv import RecordProgram, RecordProgramResponse

        self.calls: list = []
        node = f"{ns}/teach"
        self.services = [
            rospy.Service(f"{node}/record", RecordProgram, lambda req: (
                self.calls.append(("record", req.name)),
                RecordProgramResponse(success=True, message=f"recording '{req.name}' at 50 Hz"))[1]),
            rospy.Service(f"{node}/stop", Trigger, lambda req: (
                self.calls.append(("stop",)),
                TriggerResponse(success=True, message="saved program1: robot ur5, 7 waypoints"))[1]),
        ]

        def execute(goal) -> None:
            self.calls.append(("replay", goal.name, goal.speed, goal.press_axis, goal.press_force))
            self.server.set_succeeded(ReplayProgramResult(success=True, message=f"program '{goal.name}' "
                                                          "replayed at 1 x its speed; force 10.02 N"))

        self.server = actionlib.SimpleActionServer(f"{node}/replay", ReplayProgramAction, execute,
                                                   auto_start=False)
        self.server.start()

    def close(self) -> None:
        for service in self.services:
            service.shutdown()


def test_teach_box_records_stops_and_replays_through_program_server(fake, ns, make_widget, pump, ros_node):
    teach = FakeTeach(ros_node, ns)
    try:
        widget = make_widget(ns)
        box = widget.teach_box
        box.name_edit.setText("l_path")
        click(box.record_button)
        pump(lambda: teach.calls == [("record", "l_path")], message="the record call")
        recording = "Record done: recording 'l_path' at 50 Hz"
        pump(lambda: widget.answer_label.text() == recording, message="the record answer")
        click(box.stop_button)
        pump(lambda: "saved program1" in widget.answer_label.text(), message="the stop answer")
        box.speed_spin.setValue(0.5)
        box.press_spin.setValue(10.0)
        click(box.replay_button)
        pump(lambda: len(teach.calls) == 3, timeout=20, message="the replay goal")
        assert teach.calls[2] == ("replay", "l_path", 0.5, "z", 10.0)
        pump(lambda: "replayed at 1 x its speed" in widget.answer_label.text(), timeout=20,
             message="the replay's result")
        assert widget.answer_label.text().startswith("Replay done")
    finally:
        teach.close()


class FakeTaskServer:
    """task_server's ~execute action: feedback in step 'search' until cancelled, which it reports."""

    def __init__(self, rospy, ns: str) -> None:
        import actionlib
        from compliant_control_msgs.msg import ExecuteTaskAction

        self.rospy = rospy
        self.server = actionlib.SimpleActionServer(f"{ns}/task_server/execute", ExecuteTaskAction,
                                                   self._execute, auto_start=False)
        self.server.start()

    def _execute(self, goal) -> None:
        from compliant_control_msgs.msg import ExecuteTaskFeedback, ExecuteTaskResult

        feedback = ExecuteTaskFeedback(step="search", elapsed=0.0, depth=0.0003, search_radius=0.0021)
        feedback.wrench.force.z = 7.0
        while not self.server.is_preempt_requested() and not self.rospy.is_shutdown():
            feedback.elapsed += 0.1
            self.server.publish_feedback(feedback)
            self.rospy.sleep(0.1)  # the fake task's pace
        self.server.set_preempted(ExecuteTaskResult(outcome="cancelled", message="cancelled in step 'search'",
                                                    steps=["approach", "search"], step_times=[1.5, 2.0],
                                                    peak_force=8.2, peak_torque=0.05))


def test_task_box_shows_a_task_another_client_runs_and_cancels_it(fake, ns, make_widget, pump, ros_node):
    """A task started from the command line shows its step and numbers; Cancel task ends it."""
    import actionlib
    from compliant_control_msgs.msg import ExecuteTaskAction, ExecuteTaskGoal

    tasks = FakeTaskServer(ros_node, ns)
    widget = make_widget(ns)
    box = widget.task_box
    assert box.task_label.text() == "no task yet" and not box.cancel_button.isEnabled()
    client = actionlib.SimpleActionClient(f"{ns}/task_server/execute", ExecuteTaskAction)
    assert client.wait_for_server(ros_node.Duration(10.0))
    pump(lambda: widget.client._task_cancel.get_num_connections() > 0, message="Cancel's link to the server")
    client.send_goal(ExecuteTaskGoal(task="peg_in_hole"))
    pump(lambda: "step search" in box.task_label.text(), message="the task's feedback")
    assert box.task_label.text().startswith("peg_in_hole: step search, ")
    assert box.task_label.text().endswith(" s, |F| 7.0 N, depth 0.3 mm, search radius 2.1 mm")
    assert box.cancel_button.isEnabled()
    click(box.cancel_button)
    assert client.wait_for_result(ros_node.Duration(10.0))
    assert client.get_result().outcome == "cancelled"
    pump(lambda: "cancelled" in box.task_label.text(), message="the task's result")
    assert box.task_label.text() == ("peg_in_hole: cancelled: cancelled in step 'search' (3.5 s, peak |F| "
                                     "8.2 N, |T| 0.05 Nm)")
    assert not box.cancel_button.isEnabled() and not tasks.server.is_active()
