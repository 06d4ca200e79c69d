"""CompliantPipeline with no ROS master: the UR5 and Panda packages' own configuration and description, a
perfect arm that executes each joint command, and generated wrenches (tool weight + a push)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from contact_control.axes import SAFETY_ZEROING
from harness.pipeline_cell import DT, Cell
from jog_arm.status import StatusCode

DAMPING = 30.0  # [N/(m/s)] follower on Z: 4 N -> 0.133 m/s


@pytest.fixture(scope="module", params=["ur5", "panda"])
def robot(request: pytest.FixtureRequest) -> str:
    return request.param


@pytest.fixture
def cell(robot: str) -> Cell:
    c = Cell(robot)
    for _ in range(150):  # the tool's weight only: zeroed on the first 0.2 s at start-up
        c.step((0.0, 0.0, 0.0))
    assert c.pipeline.contact.ctrl.last_result.safety == 0, c.pipeline.contact.ctrl.last_result.message
    return c


def test_a_push_up_moves_the_tool_up_at_force_over_damping(cell: Cell) -> None:
    cell.follower_z()
    z0 = cell.pose("tool_tip")[:3, 3]
    for _ in range(500):  # 1 s of a 4 N push up
        cell.step((0.0, 0.0, 4.0))
    moved = cell.pose("tool_tip")[:3, 3] - z0
    # F/b = 0.133 m/s, reached after ~0.35 s of the 0.4 m/s^2 acceleration limit and the 5 Hz filter
    assert 0.07 < moved[2] < 0.133, f"tool moved {moved} m"
    assert abs(moved[0]) < 0.003 and abs(moved[1]) < 0.003, f"sideways drift {moved} m"


def test_a_push_down_moves_it_down(cell: Cell) -> None:
    cell.follower_z()
    z0 = cell.pose("tool_tip")[2, 3]
    for _ in range(250):
        cell.step((0.0, 0.0, -4.0))
    assert cell.pose("tool_tip")[2, 3] < z0 - 0.02


def test_a_stale_wrench_brings_the_arm_to_rest_and_then_silence(cell: Cell) -> None:
    cell.follower_z()
    for _ in range(300):
        cell.step((0.0, 0.0, 4.0))
    assert max(map(abs, cell.commands[-1][1])) > 0.05, "the arm was not moving before the data stopped"
    stop = cell.t
    for _ in range(250):  # 0.5 s without wrenches: stale after wrench_timeout, then the halt sequence
        cell.step(None)
    moving = [t for t, v in cell.commands if t > stop and max(map(abs, v)) > 1e-9]
    last_moving = max(moving, default=stop)
    timeout = cell.cc.wrench_timeout
    assert last_moving - stop < timeout + 0.15, f"still moving {last_moving - stop:.3f} s on"
    assert cell.commands[-1][1] == (0.0,) * len(cell.names), "the last command is not a full stop"
    assert cell.commands[-1][0] < cell.t - 0.1, "zero commands are still being sent: no silence after halt"
    assert cell.pipeline.contact.status()[0].safety != 0


def test_a_nan_wrench_yields_a_zero_twist_at_once(cell: Cell) -> None:
    cell.follower_z()
    for _ in range(300):
        twist = cell.step((0.0, 0.0, 4.0))
    assert twist is not None and twist[2] > 0.05
    assert cell.step((0.0, 0.0, 4.0), nan=True) == (0.0,) * 6
    before = abs(cell.commands[-2][1][1]) + abs(cell.commands[-2][1][2])
    after = abs(cell.commands[-1][1][1]) + abs(cell.commands[-1][1][2])
    assert after < before, "the joint command did not start to slow down"
    assert cell.pipeline.contact.ctrl.move_active, "a NaN holds; it does not end the move"


def test_an_outside_twist_moves_the_arm_and_its_echo_is_dropped(cell: Cell) -> None:
    p = cell.pipeline
    frame = cell.cc.fixed_frame
    x0 = cell.pose("tool_tip")[0, 3]
    for _ in range(200):
        cell.t += DT
        p.on_joint_state(cell.names, cell.q.tolist(), cell.t)
        cell._apply(p.on_twist((0.05, 0.0, 0.0, 0.0, 0.0, 0.0), frame, cell.t, cell.t))
    assert cell.pose("tool_tip")[0, 3] > x0 + 0.01
    # A copy of the pipeline's own twist (same stamp and values) changes nothing.
    cell.follower_z()
    twist = cell.step((0.0, 0.0, 4.0))
    assert twist is not None
    echo = p.on_twist(twist, frame, cell.t, cell.t + 0.0003)
    assert echo.cycle is None


def test_a_clock_jump_back_halts_until_a_fresh_joint_state(cell: Cell) -> None:
    cell.follower_z()
    for _ in range(300):
        cell.step((0.0, 0.0, 4.0))
    cell.t -= 5.0
    out = cell.pipeline.on_joint_state(cell.names, cell.q.tolist(), cell.t)  # the first input after it
    assert out.twist == (0.0,) * 6
    assert out.cycle is not None and out.cycle.status == StatusCode.STALE_JOINT_STATE
    assert "clock jumped back" in out.cycle.message
    twist = cell.step((0.0, 0.0, 4.0))
    assert twist is not None and twist[2] < 0.005, "the move did not restart from rest"
    for _ in range(300):  # data after the jump: the move goes on
        twist = cell.step((0.0, 0.0, 4.0))
    assert twist is not None and twist[2] > 0.05


@pytest.mark.parametrize("module", ["control_stack.pipeline", "contact_control.stage", "jog_arm.stage"])
def test_the_core_imports_no_rospy(module: str) -> None:
    code = (f"import sys, {module}; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('rospy', 'tf2_ros')]; "
            "print(bad); sys.exit(1 if bad else 0)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, f"{module} imports {run.stdout or run.stderr}"


def test_requests_are_answered_with_the_reason_and_a_stop_halts_the_arm(cell: Cell) -> None:
    from cartesian_impedance_msgs.msg import ControlLaw
    from cartesian_impedance_msgs.srv import ConfigureForceControlRequest

    p = cell.pipeline
    bad = ConfigureForceControlRequest()
    bad.direction_control_laws.z.type = ControlLaw.TYPE_FOLLOWER  # no damping: refused
    answer = p.configure(bad, cell.t)
    assert not answer.ok and "damping" in answer.message
    assert not p.contact.ctrl.move_active, "a refused request changed something"
    good = ConfigureForceControlRequest()
    good.cart_impedance_params.damping.translational.z = DAMPING
    good.direction_control_laws.z.type = ControlLaw.TYPE_FOLLOWER
    answer = p.configure(good, cell.t)
    assert answer.ok and "z=follower" in answer.message, answer
    for _ in range(200):
        cell.step((0.0, 0.0, 4.0))
    status = p.status()
    assert status.contact.move_active
    assert status.jog is not None and status.jog.status == StatusCode.NO_WARNING
    out = p.stop("test", cell.t)
    assert out.twist == (0.0,) * 6 and out.cycle is not None
    assert not p.contact.ctrl.move_active
    cell.step((0.0, 0.0, 4.0))
    assert not p.status().contact.move_active  # the status shows the last cycle
    for _ in range(200):  # the push goes on; the stopped move does not follow it
        cell.step((0.0, 0.0, 4.0))
    assert cell.commands[-1][1] == (0.0,) * len(cell.names)


def test_a_law_set_while_the_sensor_is_zeroed_says_so_and_waits(robot: str) -> None:
    from cartesian_impedance_msgs.msg import ControlLaw
    from cartesian_impedance_msgs.srv import ConfigureForceControlRequest

    cell = Cell(robot)  # no wrench yet: start-up zeroing has not begun
    req = ConfigureForceControlRequest()
    req.cart_impedance_params.damping.translational.z = DAMPING
    req.direction_control_laws.z.type = ControlLaw.TYPE_FOLLOWER
    answer = cell.pipeline.configure(req, cell.t)
    assert answer.ok and "still being zeroed" in answer.message and "keep the tool free" in answer.message
    cell.step(None)  # the first joint state
    tip = cell.pose(cell.cc.eef_frame)[:3, 3]
    for _ in range(90):  # the free sensor for 0.18 s: still zeroing, the law holds still
        cell.step((0.0, 0.0, 0.0))
    assert cell.pipeline.contact.ctrl.last_result.safety == SAFETY_ZEROING
    for _ in range(60):  # zeroed; then a push up is followed
        cell.step((0.0, 0.0, 0.0))
    assert np.linalg.norm(cell.pose(cell.cc.eef_frame)[:3, 3] - tip) < 1e-6
    for _ in range(300):
        cell.step((0.0, 0.0, 4.0))
    assert cell.pose(cell.cc.eef_frame)[2, 3] - tip[2] > 0.02
    answer = cell.pipeline.configure(req, cell.t)
    assert answer.ok and "zeroed" not in answer.message, "said only while zeroing"
