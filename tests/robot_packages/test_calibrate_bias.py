"""`rosrun control_stack calibrate_bias` on the simulated UR5: it moves the arm through a sweep of poses
(named_poses), samples the wrench at rest, and writes a bias map contact_control loads. The simulated
sensor's only error is none: the map must find no load error (the configured 1 kg tool is taken out) and
leave little on the held-out poses; then sim.launch with bias_map:= starts with it and zeroes."""

from __future__ import annotations

import subprocess

import pytest

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")

from contact_control.bias_map import load_bias_map
from harness.launch import run_launch


def test_a_sweep_writes_a_map_of_the_sensor_as_it_is(ros_node, tmp_path):
    path = tmp_path / "bias_map.yaml"
    with run_launch("ur5_custom", "sim.launch") as h:
        h.wait_for_service("/named_poses/move_to_joints", timeout=40)
        h.wait_for_topic("/joint_states", timeout=40)
        done = subprocess.run(
            ["rosrun", "control_stack", "calibrate_bias", "--output", str(path), "--count", "12",
             "--box=-0.05,0.05,-0.05,0.05,0.0,0.05", "--tilt", "0.25", "--speed-scale", "1"],
            capture_output=True, text=True, timeout=240)
        assert done.returncode == 0, done.stdout + done.stderr + h.output()[-2000:]
    print("\n" + done.stdout.splitlines()[-2])
    fitted = load_bias_map(str(path))
    assert fitted.samples >= 10 and fitted.frame == "ft_sensor"
    assert abs(fitted.mass) < 0.03, fitted.describe()  # the configured tool is out: nothing else weighs
    assert fitted.residual_force < 0.3, fitted.describe()
    assert "calibrate_bias --output" in fitted.command
