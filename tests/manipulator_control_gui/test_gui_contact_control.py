"""The panel against the real contact_control_node (rosrun) on the session's master, default names."""

import pytest
from compliant_control_msgs.msg import ContactControlStatus
from harness.launch import run_node
from harness.waiting import Collector, wait_until
from manipulator_control_gui.form_config import load_config
from manipulator_control_gui.ros_client import RosNames


@pytest.fixture
def contact_control(ros_node):
    with run_node("contact_control", "contact_control_node", name="contact_control_node") as node:
        node.wait_for_service("/configure_cartesian_impedance", timeout=30)
        node.wait_for_service("/contact_control_node/stop", timeout=30)
        yield node


def click(button) -> None:
    from python_qt_binding.QtCore import Qt
    from python_qt_binding.QtTest import QTest

    QTest.mouseClick(button, Qt.LeftButton)


def test_apply_refusal_and_stop_with_the_real_node(contact_control, qapp, pump):
    from manipulator_control_gui.widget import ControlWidget
    from python_qt_binding.QtCore import Qt
    from python_qt_binding.QtTest import QTest

    status = Collector("/contact_control_node/status", ContactControlStatus)
    widget = ControlWidget(load_config(), RosNames(), retry_period=0.2)
    try:
        widget.show()
        pump(lambda: widget.connection_label.text().startswith("Connected"), 20, "the connection line")
        assert "/configure_cartesian_impedance" in widget.connection_label.text()
        pump(lambda: "laws via /configure_laws" in widget.connection_label.text(), 20, "ConfigureLaws")

        widget.load_preset("hybrid")
        click(widget.apply_button)
        pump(lambda: widget.answer_label.text().startswith("Applied"), 20, "the node's answer")
        # A status the timer made just before the answer can arrive after it (on a busy machine it did):
        # wait for one that shows the move.
        hybrid = {"x": 3, "y": 0, "z": 2, "rx": 0, "ry": 0, "rz": 0}

        def laws() -> dict:
            last = status.last()
            return {axis.axis: axis.law for axis in last.axes} if last is not None else {}

        wait_until(lambda: laws() == hybrid, 10, f"a status with the hybrid laws (last: {laws()})")
        pump(lambda: widget.wrench_label.text().startswith("F ["), 10, "the readout")

        # Inside the form's range (0.3 m/s) but above the node's max_velocity (0.25 m/s by default):
        # the node refuses, and the answer line gives its reason and code.
        spin = widget.rows["x"].spins["velocity"]
        spin.selectAll()
        QTest.keyClicks(spin, "0.3")
        QTest.keyClick(spin, Qt.Key_Enter)
        assert widget.form()["x"].velocity == 0.3
        click(widget.apply_button)
        pump(lambda: "(error " in widget.answer_label.text(), 20, "the refusal with its reason")
        text = widget.answer_label.text()
        assert text.startswith("Refused: axis x") and "SET_CARTESIAN_CONTROL_FAILED, -4" in text
        assert "X reads x.velocity; got 0.3" in text  # ConfigureLaws's answer names the field

        # The node still works after the refusal.
        click(widget.stop_button)
        pump(lambda: widget.answer_label.text().startswith("Stop done"), 20, "stop's answer")
    finally:
        status.close()
        widget.shutdown()
        widget.close()
        widget.deleteLater()
        qapp.processEvents()
