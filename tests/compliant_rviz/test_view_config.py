"""RViz on a robot with a tf prefix (README, Namespaces): the saved view's frames get the prefix, and
`rviz_view` hands RViz that view only when the robot's namespace has a prefix."""

from __future__ import annotations

import os
import pathlib
import subprocess

import pytest
import yaml
from compliant_rviz.view_config import prefixed_view

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
VIEW = SRC / "ur5_custom" / "config" / "view.rviz"


def test_the_fixed_frame_and_the_robot_model_get_the_prefix_and_the_file_is_unchanged():
    view = yaml.safe_load(VIEW.read_text())
    out = prefixed_view(view, "/left/")
    manager = out["Visualization Manager"]
    assert manager["Global Options"]["Fixed Frame"] == "left/base_link"
    models = [d for d in manager["Displays"] if d["Class"] == "rviz/RobotModel"]
    assert models and all(d["TF Prefix"] == "left" for d in models)
    grid = next(d for d in manager["Displays"] if d["Class"] == "rviz/Grid")
    assert grid["Reference Frame"] == "<Fixed Frame>"  # RViz's own placeholder stays
    assert view["Visualization Manager"]["Global Options"]["Fixed Frame"] == "base_link"
    assert prefixed_view(view, "") == view


def test_the_saved_views_read_their_topics_in_the_robots_namespace():
    for path in sorted(SRC.glob("*_custom/config/view.rviz")):
        text = path.read_text()
        topics = [line.split(":", 1)[1].strip() for line in text.splitlines() if "Topic:" in line]
        assert topics and not [t for t in topics if t.startswith("/")], (path, topics)


@pytest.mark.e2e  # a master
def test_rviz_view_hands_rviz_the_prefixed_view_in_a_namespace_with_a_prefix(roscore, tmp_path):
    """A stand-in `rviz` on PATH writes down the view it was given."""
    import xmlrpc.client

    fake = tmp_path / "bin" / "rviz"
    fake.parent.mkdir()
    fake.write_text("#!/bin/sh\nfor a; do [ \"$prev\" = -d ] && cp \"$a\" \"$SEEN\"; prev=$a; done\n")
    fake.chmod(0o755)
    master = xmlrpc.client.ServerProxy(roscore.uri)
    master.setParam("/test", "/cell_left/tf_prefix", "cell_left")
    try:
        for ns, frame in (("/cell_left", "cell_left/base_link"), ("/cell_plain", "base_link")):
            seen = tmp_path / f"seen{ns.replace('/', '_')}.rviz"
            env = dict(roscore.env, PATH=f"{fake.parent}:{os.environ['PATH']}", ROS_NAMESPACE=ns,
                       SEEN=str(seen))
            run = subprocess.run(["rosrun", "compliant_rviz", "rviz_view", "-d", str(VIEW), "__name:=rviz"],
                                 env=env, capture_output=True, text=True, timeout=60, check=False)
            assert run.returncode == 0, run.stderr
            view = yaml.safe_load(seen.read_text())
            assert view["Visualization Manager"]["Global Options"]["Fixed Frame"] == frame
    finally:
        master.deleteParam("/test", "/cell_left/tf_prefix")
