"""Payload identification on the simulated arms: `rosrun contact_control identify_payload robot` tilts the
tool through seven orientations by jogging, samples the wrench at each, and fits the tool the robot package
configured (1.0 kg, centre of mass 0.05 m out along the sensor's Z) within 5 % and 5 mm."""

from __future__ import annotations

import pathlib
import re
import subprocess

import numpy as np
import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

import yaml
from harness.launch import run_launch

CONFIG = {"ur5_custom": "src/ur5_custom/config/contact_control.yaml",
          "panda_custom": "src/panda_custom/config/contact_control.yaml"}


@pytest.mark.parametrize("robot", ["ur5_custom", "panda_custom"])
def test_identify_recovers_the_configured_tool(ros_node, robot):
    config = yaml.safe_load((pathlib.Path(__file__).resolve().parents[2] / CONFIG[robot]).read_text())
    with run_launch(robot, "sim.launch") as h:
        h.wait_for_service("/contact_control_node/payload/identify", timeout=40)
        h.wait_for_topic("/joint_states", timeout=40)
        done = subprocess.run(["rosrun", "contact_control", "identify_payload", "robot"],
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stdout + done.stderr + h.output()[-2000:]
    fitted = yaml.safe_load(done.stdout[done.stdout.index("tool_mass:"):])
    print(f"\n{robot}: " + re.search(r"mass .*condition [\d.]+", done.stdout).group(0))
    assert fitted["tool_mass"] == pytest.approx(config["tool_mass"], rel=0.05)
    assert np.linalg.norm(np.subtract(fitted["tool_com"], config["tool_com"])) < 0.005
