"""Work done ahead or cached per joint state (prefetch, ModelFrames) must never change an answer."""

from __future__ import annotations

import numpy as np
import pytest
from jog_arm.model_frames import ModelFrames
from jog_arm_testing import Robot, make_jog


def _run(robot: Robot, integrate_from: str, prefetch: bool) -> tuple[list[tuple[float, ...]], int]:
    """Twists in the tip frame (its rotation comes from the model's data) toward a near-singular pose;
    the joint state is set after prefetch, so measured mode also meets a prefetch made stale."""
    jog = make_jog(robot, integrate_from=integrate_from, singularity_threshold=6.0)
    calls = 0
    jacobian = jog.model.jacobian

    def counted(q: np.ndarray) -> np.ndarray:
        nonlocal calls
        calls += 1
        return jacobian(q)

    jog.model.jacobian = counted  # type: ignore[method-assign]
    q = np.array(robot.near_singular, dtype=float)
    jog.set_joint_state(q)
    outputs = []
    for k in range(150):
        t = k * 0.01
        twist = (0.05, -0.02, 0.03, 0.0, 0.2, 0.0) if k < 100 else (0.0,) * 6
        jog.set_command(twist, robot.tip, t)
        steps_before = calls
        out = jog.step(t)
        outputs.append((*out.positions, *out.velocities, out.condition_number, out.speed_scale))
        predicted = out.condition_number > 6.0  # the singularity check's look-ahead moves the model's data
        if prefetch and k > 5 and integrate_from == "commanded" and k < 100 and not predicted:
            assert calls == steps_before, f"cycle {k} recomputed the prefetched Jacobian"
        if prefetch:
            jog.prefetch()
        if out.publish:
            jog.set_joint_state(np.asarray(out.positions) + 1e-4 * np.sin(k))  # not exactly as commanded
    return outputs, calls


@pytest.mark.parametrize("integrate_from", ["commanded", "measured"])
def test_prefetch_gives_the_commands_of_computing_in_the_cycle(robot: Robot, integrate_from: str) -> None:
    plain, _ = _run(robot, integrate_from, prefetch=False)
    ahead, _ = _run(robot, integrate_from, prefetch=True)
    assert np.array(ahead) == pytest.approx(np.array(plain), rel=0, abs=1e-12)
    assert min(row[-1] for row in plain) < 1.0, "the run never came near the singularity it should test"


def test_model_frames_follow_each_new_joint_state(robot: Robot) -> None:
    jog = make_jog(robot)
    frames = ModelFrames(jog.model, lambda: jog.measured)
    with pytest.raises(LookupError):
        frames.pose(robot.tip, robot.planning_frame)
    assert frames.pose("no_such_frame", robot.planning_frame) is None
    for q in (robot.start, robot.near_singular):
        jog.set_joint_state(q)
        for _ in range(2):  # the second answer comes from the per-state cache
            pose = np.array(frames.pose(robot.tip, robot.planning_frame))
            expected = jog.eef_pose(q)  # tip in the planning frame, computed afresh
            assert pose[:3, :3] == pytest.approx(expected.rotation, abs=1e-12)
            assert pose[:3, 3] == pytest.approx(expected.translation, abs=1e-12)
