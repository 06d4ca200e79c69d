"""The standalone node (rosrun): starts, follows its parameters, quits on Ctrl-C."""

import os
import xmlrpc.client

from harness.launch import run_node
from harness.waiting import wait_until


def offscreen_env() -> dict:
    return {**os.environ, "QT_QPA_PLATFORM": "offscreen"}


def subscribers(topic: str) -> list:
    _, _, (_, subs, _) = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"]).getSystemState("/test")
    return next((nodes for name, nodes in subs if name == topic), [])


def test_standalone_node_subscribes_where_its_parameters_say_and_quits_cleanly(roscore):
    params = {"~contact_control_node": "/arm/contact_control_node"}
    with run_node(
        "manipulator_control_gui",
        "manipulator_control_gui",
        params=params,
        name="control_panel",
        env=offscreen_env(),
    ) as node:
        wait_until(
            lambda: (
                "/control_panel" in subscribers("/arm/contact_control_node/status")
                or node.proc.poll() is not None
            ),
            timeout=30,
            message="the panel's status subscriber",
        )
        assert node.proc.poll() is None, node.output()
        node.stop()
        assert node.proc.returncode == 0, node.output()


def test_a_bad_form_config_stops_the_node_with_the_key_named(roscore, tmp_path):
    bad = tmp_path / "gui.yaml"
    bad.write_text("fields: {}\nlaws: {}\n")
    with run_node(
        "manipulator_control_gui",
        "manipulator_control_gui",
        params={"~config": str(bad)},
        name="control_panel_bad",
        env=offscreen_env(),
    ) as node:
        wait_until(lambda: node.proc.poll() is not None, timeout=30, message="the node to exit")
        assert node.proc.returncode != 0
        assert "gui config 'fields.damping'" in node.output()
