"""`roslaunch ur5_custom sim.launch viewer:=rviz` on a private display: RViz opens on the package's
view, stack_markers draws the obstacle where the scene has it, the laws per axis, the commanded velocity and
the push while the tool follows one, and the screenshot shows the robot (not a blank window). Set
COMPLIANT_RVIZ_WRITE_SCREENSHOT=1 to refresh the README's figure (src/compliant_rviz/doc/view.png)."""

from __future__ import annotations

import contextlib
import os
import pathlib
import shutil

import numpy as np
import pytest
import yaml
from harness.display import HAVE_XVFB, NO_XVFB, private_display, screenshot, windows
from harness.launch import run_launch
from harness.rviz import named
from harness.waiting import Collector, wait_until

pytest.importorskip("cartesian_impedance_msgs.srv", reason="needs devel/setup.bash (make test sources it)")
pytestmark = [pytest.mark.skipif(not HAVE_XVFB, reason=NO_XVFB),
              pytest.mark.skipif(not shutil.which("rviz"), reason="needs rviz (bootstrap installs it)")]

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
FIGURE = SRC / "compliant_rviz" / "doc" / "view.png"


def _counts(picture) -> tuple[int, int, float]:
    """(red pixels: the tool (URDF red) and the obstacle marker; pixels of the 3-D view's grey background;
    the picture's standard deviation)."""
    from PIL import Image

    image = np.asarray(Image.open(picture).convert("RGB")).astype(int)
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    red = int(np.sum((r > 150) & (g < 90) & (b < 90)))
    grey = int(np.sum((abs(r - 48) < 6) & (abs(g - 48) < 6) & (abs(b - 48) < 6)))
    return red, grey, float(image.std())


def test_viewer_rviz_shows_the_robot_the_laws_the_velocity_and_the_push(ros_node, tmp_path):
    from cartesian_impedance_msgs.msg import ControlLaw
    from cartesian_impedance_msgs.srv import ConfigureForceControl, ConfigureForceControlRequest
    from compliant_control_msgs.msg import ContactControlStatus
    from compliant_control_msgs.srv import PushEEF, PushEEFRequest
    from visualization_msgs.msg import MarkerArray

    rospy = ros_node
    scene = yaml.safe_load((SRC / "ur5_custom" / "config" / "sim.yaml").read_text())
    with private_display() as display:
        env = {**os.environ, "DISPLAY": display}
        for key in ("WAYLAND_DISPLAY", "QT_QPA_PLATFORM"):  # the GUI tests' conftest sets Qt offscreen
            env.pop(key, None)
        markers = Collector("/stack_markers/markers", MarkerArray)
        try:
            with run_launch("ur5_custom", "sim.launch", args={"viewer": "rviz"}, env=env) as h:
                h.wait_for_service("/configure_cartesian_impedance", timeout=40)
                try:
                    wait_until(lambda: "RViz" in windows(display), 60, "RViz's window")
                except AssertionError as err:  # what RViz and the stack said
                    raise AssertionError(f"{err}; windows: {windows(display)[-1500:]}; launch output: "
                                         f"{h.output()[-4000:]}") from None
                status = "/contact_control_node/status"
                wait_until(lambda: rospy.wait_for_message(status, ContactControlStatus, 5).safety == 0, 20,
                           "the sensor zeroed")

                def idle() -> bool:
                    last = markers.last()
                    laws = named(last, "laws")
                    return named(last, "obstacle") is not None and laws is not None and "no law" in laws.text

                wait_until(idle, 20, "the obstacle and 'no law'")
                box = named(markers.last(), "obstacle")
                p = box.pose.position
                assert (p.x, p.y, p.z) == pytest.approx(scene["obstacle"]["position"])
                assert (box.scale.x, box.scale.y, box.scale.z) == pytest.approx(scene["obstacle"]["size"])
                assert named(markers.last(), "push") is None and named(markers.last(), "velocity") is None

                req = ConfigureForceControlRequest()
                req.cart_impedance_params.damping.translational.x = 200.0
                req.direction_control_laws.x.type = ControlLaw.TYPE_FOLLOWER
                configure = rospy.ServiceProxy("/configure_cartesian_impedance", ConfigureForceControl)
                assert configure(req).success
                push = PushEEFRequest(duration=2.0)
                push.wrench.force.x = -10.0
                assert rospy.ServiceProxy("/mujoco_driver/push", PushEEF)(push).success

                def following() -> bool:
                    last = markers.msgs[-3:]
                    arrows = [named(a, "velocity") for a in last]
                    pushes = [named(a, "push") for a in last]
                    return len(last) == 3 and all(arrows) and all(pushes) and all(
                        a.points[1].x < a.points[0].x for a in arrows)  # the velocity along -X

                wait_until(following, 10, "the velocity and push arrows along -X, three times running")
                text = named(markers.last(), "laws").text
                assert text.startswith("x: follower") and "mm/s" in text, text
                wait_until(lambda: "speed cap" in named(markers.last(), "laws").text, 5,
                           "jog_arm's speed cap in the text while the tool moves")
                assert "(hand, ISO/TS 15066)" in named(markers.last(), "laws").text
                push_arrow = named(markers.last(), "push")
                assert push_arrow.points[1].x < push_arrow.points[0].x  # drawn pushing toward -X
                picture = tmp_path / "rviz.png"
                seen: list[tuple[int, int, float]] = []

                def drawn() -> bool:  # RViz draws its 3-D view some frames after its window is mapped
                    screenshot(display, str(picture))
                    seen.append(_counts(picture))
                    red, grey, std = seen[-1]
                    return std > 20 and grey > 50_000 and red > 500

                with contextlib.suppress(AssertionError):  # the assertions below say what was missing
                    wait_until(drawn, 30, "RViz's 3-D view drawn")
                wait_until(lambda: named(markers.last(), "push") is None, 10, "no push arrow after the push")
                h.stop()
        finally:
            markers.close()

    red, grey, std = seen[-1]
    print(f"\n{len(seen)} screenshot(s), the last: {red} red pixels, {grey} background, std {std:.1f}")
    assert std > 20, "a blank screen"
    assert grey > 50_000, "no 3-D view (RViz's background) on the screen"
    assert red > 500, "neither the tool nor the obstacle is drawn"
    if os.environ.get("COMPLIANT_RVIZ_WRITE_SCREENSHOT"):
        FIGURE.parent.mkdir(exist_ok=True)
        shutil.copyfile(picture, FIGURE)
