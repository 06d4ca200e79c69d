"""The two simulated robots with a person's hand in the scene (mujoco_driver's `hand` or `free_hand`
fixture), for the cobot_safety tests: the UR5 in the default single process, the Panda in the two-node
layout (the force over a topic)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from harness.launch import Launched, run_launch

LAYOUTS = [("ur5_custom", True), ("panda_custom", False)]  # (package, single_process)
BASE_FRAME = {"ur5_custom": "base_link", "panda_custom": "panda_link0"}


@contextmanager
def hand_scene(robot: str, single_process: bool, fixture: str) -> Iterator[Launched]:
    """sim.launch with the fixture, once the tool's pose, the wrench and jog_arm's status flow."""
    args = {"single_process": str(single_process).lower(), "fixture": fixture}
    with run_launch(robot, "sim.launch", args=args) as h:
        for topic in ("/mujoco_driver/eef_pose", "/wrench", "/jog_arm_server/status"):
            h.wait_for_topic(topic, timeout=40)
        try:
            yield h
        except AssertionError as err:  # a lockstep given up on, a dropped backlog: why a run went wrong
            err.add_note(f"the launch's warnings:\n{h.warnings()}")
            raise
