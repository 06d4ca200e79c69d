"""JogCalcs under a real cell's faults: a dead driver (stale joint state), a vanished command source, clock
jumps, a lost master. Each must stop the arm within the acceleration limits and resume cleanly."""

from __future__ import annotations

import numpy as np
import pytest
from jog_arm_testing import Robot, make_jog

from jog_arm import StatusCode

TWIST = (0.05, 0.0, 0.0, 0.0, 0.0, 0.0)  # 5 cm/s along X


class Cell:
    """A JogCalcs fed by a driver that streams its (perfectly tracked) joint state every cycle, stamped."""

    def __init__(self, robot: Robot, **params) -> None:
        self.jog = make_jog(robot, joint_state_timeout=0.05, **params)
        self.period = self.jog.settings.pub_period
        self.q = np.array(robot.start, dtype=float)
        self.t = 0.0
        self.driver_alive = True
        self.jog.set_joint_state(self.q, self.t)
        self.status: list[StatusCode] = []
        self.messages: list[str] = []
        self.speeds: list[float] = []

    def run(self, seconds: float, twist=TWIST) -> None:
        for _ in range(round(seconds / self.period)):
            if twist is not None:
                self.jog.set_command(twist, "", self.t)
            out = self.jog.step(self.t)
            dq = np.array(out.velocities) if out.publish else np.zeros(self.jog.nv)
            self.q = self.q + dq * self.period  # the arm follows the velocity (a dead driver's arm too)
            self.t += self.period
            if self.driver_alive:
                self.jog.set_joint_state(self.q, self.t)
            self.status.append(out.status)
            self.messages.append(out.message)
            self.speeds.append(float(np.abs(dq).max()))

    def tip(self) -> np.ndarray:
        return self.jog.eef_pose(self.q).translation.copy()


def test_a_dead_driver_stops_the_arm_and_a_fresh_state_resumes_it_without_a_jump(robot: Robot) -> None:
    cell = Cell(robot)
    cell.run(1.0)
    assert cell.speeds[-1] > 0.0
    cell.driver_alive = False
    before = cell.tip()
    cell.run(1.0)
    assert StatusCode.STALE_JOINT_STATE in cell.status[-100:]
    assert "no joint state" in cell.messages[-1]
    assert cell.speeds[-1] == 0.0  # at rest while the state is stale, although twists keep coming
    assert np.linalg.norm(cell.tip() - before) < 0.005  # 5 cm/s stopped within 5 mm
    max_step = np.max(cell.jog.limiter.max_acceleration) * cell.period * (1 + 1e-9)
    assert np.abs(np.diff(cell.speeds)).max() <= max_step  # decelerated, no jump to zero
    cell.driver_alive = True
    cell.jog.set_joint_state(cell.q, cell.t)
    n = len(cell.speeds)
    cell.run(1.0)
    assert cell.status[-1] == StatusCode.NO_WARNING and cell.speeds[-1] > 0.0
    assert np.abs(np.diff(cell.speeds[n - 1 :])).max() <= max_step  # resumed without a jump


def test_a_hung_command_source_stops_the_arm_within_8_mm_after_the_timeout(robot: Robot) -> None:
    """The robot packages' set-up (incoming_cmd_timeout 0.1 s) jogging at 5 cm/s: twists stop coming (the
    source hung, its connection open); 5 mm run on within the timeout, then a ramp down within the
    acceleration limits. tests/robot_packages/test_robot_faults.py runs the same on the simulated arms."""
    cell = Cell(robot, incoming_cmd_timeout=0.1)
    cell.run(1.0)
    assert cell.speeds[-1] > 0.0
    start = cell.tip()
    cell.run(1.0, twist=None)
    assert cell.speeds[-1] == 0.0 and StatusCode.STALE_COMMAND in cell.status[-100:]
    assert np.linalg.norm(cell.tip() - start) < 0.008


def test_a_dropped_command_stops_at_once_not_after_the_timeout(robot: Robot) -> None:
    cell = Cell(robot, incoming_cmd_timeout=1.0)
    cell.run(1.0)
    start = cell.tip()
    cell.jog.drop_command("the command's publisher disconnected")
    cell.run(1.0, twist=None)
    assert cell.speeds[-1] == 0.0
    assert np.linalg.norm(cell.tip() - start) < 0.005
    assert any("publisher disconnected" in m for m in cell.messages[-100:])
    cell.run(0.5)  # a new command moves it again
    assert cell.speeds[-1] > 0.0


def test_a_clock_jump_drops_the_command_and_waits_for_a_fresh_joint_state(robot: Robot) -> None:
    cell = Cell(robot)
    cell.run(0.5)
    cell.jog.clock_jumped("clock jumped back by 10.000 s")
    cell.t -= 10.0  # the clock now reads 10 s earlier; the joint state from before the jump is untrusted
    cell.driver_alive = False
    cell.run(0.5)  # twists keep coming, stamped with the new clock
    assert cell.speeds[-1] == 0.0
    assert "after the clock jump" in cell.messages[-1]
    cell.driver_alive = True
    cell.jog.set_joint_state(cell.q, cell.t)
    cell.run(0.5)
    assert cell.speeds[-1] > 0.0


def test_while_suspended_commands_are_refused_and_the_arm_stops(robot: Robot) -> None:
    cell = Cell(robot)
    cell.run(0.5)
    cell.jog.suspend("ROS master lost")
    result = cell.jog.set_command(TWIST, "", cell.t)
    assert not result.accepted and "master" in result.reason
    cell.run(0.5)
    assert cell.speeds[-1] == 0.0 and cell.status[-1] == StatusCode.PAUSED
    cell.jog.unsuspend()
    cell.run(0.5)
    assert cell.speeds[-1] > 0.0


def test_a_joint_state_without_a_time_is_never_stale(robot: Robot) -> None:
    jog = make_jog(robot, joint_state_timeout=0.05)
    jog.set_joint_state(np.array(robot.start))
    jog.set_command(TWIST, "", 10.0)
    assert jog.step(10.0).status == StatusCode.NO_WARNING


def test_the_timeout_must_be_positive(robot: Robot) -> None:
    from jog_arm import SettingsError

    with pytest.raises(SettingsError, match="joint_state_timeout"):
        make_jog(robot, joint_state_timeout=0.0)
