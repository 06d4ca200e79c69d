"""The robot's own stops (jog_arm.robot_stop): the driver's topics say the arm stopped, jog_arm holds with
nothing to decelerate, refuses commands and says why until recovered; then it moves again from where the
arm was held, without a jump."""

from __future__ import annotations

import numpy as np
import pytest
from jog_arm.robot_stop import RecoveryStep, RobotStop, StopWatch, parse_robot_stop
from jog_arm.settings import JogSettings, SettingsError
from jog_arm.stage import JogStage
from jog_arm.status import StatusCode
from jog_arm_testing import Robot

pytestmark = pytest.mark.cobot_safety

UR = {"watch": [{"topic": "ur_hardware_interface/safety_mode", "type": "ur_dashboard_msgs/SafetyMode",
                 "field": "mode", "running": [1, 2]},
                {"topic": "ur_hardware_interface/robot_program_running", "type": "std_msgs/Bool",
                 "field": "data", "running": [True]}],
      "recover": ["ur_hardware_interface/dashboard/unlock_protective_stop",
                  "ur_hardware_interface/resend_robot_program"]}


def test_the_parameter_names_topics_and_recovery_services_and_bad_ones_are_refused_by_key():
    watches, services = parse_robot_stop(UR, "/jog_arm_server/")
    assert [w.topic for w in watches] == ["ur_hardware_interface/safety_mode",
                                          "ur_hardware_interface/robot_program_running"]
    assert watches[0].running == (1, 2) and services == tuple(RecoveryStep(name) for name in UR["recover"])
    assert parse_robot_stop({}) == ((), ())
    franka = {"watch": [{"topic": "franka_state_controller/franka_states", "type": "franka_msgs/FrankaState",
                         "field": "robot_mode", "running": [1, 2]}],
              "recover": [{"action": "franka_control/error_recovery",
                           "type": "franka_msgs/ErrorRecoveryAction"}]}
    assert parse_robot_stop(franka)[1] == (RecoveryStep("franka_control/error_recovery",
                                                        "franka_msgs/ErrorRecoveryAction"),)
    bad = [({"watch": [{"topic": "t", "type": "p/M", "field": "f"}]}, r"watch\[0\]"),
           ({"watch": [{"topic": "t", "type": "M", "field": "f", "running": [1]}]}, "package/Message"),
           ({"watch": [{"topic": "t", "type": "p/M", "field": "f", "running": []}]}, r"watch\[0\]\.running"),
           ({"recover": ["s"]}, "needs watch entries"),
           ({"watch": [], "recover": "s"}, r"robot_stop\.recover"),
           ({"watch": UR["watch"], "recover": [{"action": "a", "type": "p/Goal"}]}, r"recover\[0\]: "),
           ({"watch": UR["watch"], "recover": [3]}, r"recover\[0\]"),
           ({"other": 1}, "keys watch and recover")]
    for params, message in bad:
        with pytest.raises(SettingsError, match=message):
            parse_robot_stop(params, "/jog_arm_server/")


def test_a_stop_is_latched_until_the_driver_runs_and_recovery_is_asked_for():
    stop = RobotStop(parse_robot_stop(UR)[0])
    assert not stop.update(0, 1, "NORMAL") and not stop.update(1, True)
    assert stop.update(0, 3, "PROTECTIVE_STOP") and "safety_mode reads PROTECTIVE_STOP (3)" in stop.reason
    assert not stop.update(1, False)  # already stopped: one stop, one reason
    ok, why = stop.recover()
    assert not ok and "still reports a stop" in why and "robot_program_running: False" in why
    assert not stop.update(0, 1, "NORMAL") and not stop.update(1, True)
    assert stop.reason  # the driver runs again, but nobody asked to recover: still latched
    assert stop.recover() == (True, "recovered from: the robot stopped: ur_hardware_interface/safety_mode "
                                    "reads PROTECTIVE_STOP (3)")
    assert stop.recover() == (True, "the robot was not stopped")


def test_the_cause_listed_first_names_the_stop_whichever_topic_brings_the_news_first():
    """The program stops with a protective stop; its topic may arrive first: the safety mode, listed before
    it, then names the stop. A consequence arriving after the cause changes nothing."""
    stop = RobotStop(parse_robot_stop(UR)[0])
    assert not stop.update(0, 1, "NORMAL") and not stop.update(1, True)
    assert stop.update(1, False) and "robot_program_running reads False" in stop.reason
    assert stop.update(0, 3, "PROTECTIVE_STOP") and "safety_mode reads PROTECTIVE_STOP (3)" in stop.reason
    assert not stop.update(1, False) and "PROTECTIVE_STOP" in stop.reason
    assert not stop.update(0, 1, "NORMAL") and not stop.update(1, True) and stop.recover()[0]
    assert stop.update(1, False) and "robot_program_running" in stop.reason  # after recovery: anew


def test_a_robot_not_started_yet_is_reported_and_clears_by_itself_once_it_runs():
    stop = RobotStop([StopWatch("program_running", "std_msgs/Bool", "data", (True,))])
    assert stop.state() == "program_running: not heard yet" and stop.driver_running()
    assert stop.update(0, False) and stop.reason
    assert not stop.update(0, True) and not stop.reason


class HeldCell:
    """A JogStage on an arm that follows every command until its driver stops it, then holds."""

    def __init__(self, robot: Robot) -> None:
        params = {"ee_frame_name": robot.tip, "planning_frame": robot.planning_frame,
                  "command_in_type": "speed_units", "pub_period": 0.01, "incoming_cmd_timeout": 0.5,
                  **robot.params}
        self.stage = JogStage(JogSettings.from_params(params), robot.urdf)
        self.names = self.stage.joint_names
        self.q = np.array(robot.start, dtype=float)
        self.t, self.held = 0.0, False
        self.cycles: list = []
        self.stage.on_joint_state(self.names, self.q.tolist(), self.t)

    def run(self, seconds: float, twist=(0.1, 0.0, 0.0, 0.0, 0.0, 0.0)) -> None:
        for _ in range(round(seconds / 0.01)):
            self.stage.on_twist(twist, "", self.t, outside=False)
            cycle = self.stage.tick(self.t)
            if cycle is not None:
                self.cycles.append(cycle)
                if cycle.publish and not self.held:
                    self.q = np.array(cycle.positions)
            self.t += 0.01
            self.stage.on_joint_state(self.names, self.q.tolist(), self.t)

    def tip(self, q=None) -> np.ndarray:
        return self.stage.jog.eef_pose(self.q if q is None else q).translation.copy()


def test_a_stop_holds_refuses_commands_says_why_and_recovery_moves_on_without_a_jump(robot: Robot):
    cell = HeldCell(robot)
    cell.run(0.5)
    moving = cell.tip()
    assert np.linalg.norm(moving - cell.tip(np.array(robot.start))) > 0.03  # 0.1 m/s for 0.5 s
    cell.held = True  # the driver holds the arm from now on
    cell.stage.robot_stopped("the robot stopped: ur_hardware_interface/safety_mode reads PROTECTIVE_STOP (3)")
    assert ("error", "the robot stopped: ur_hardware_interface/safety_mode reads PROTECTIVE_STOP (3): "
            "holding; commands are refused until recovered") in cell.stage.notes
    start = len(cell.cycles)
    cell.run(0.1)  # twists keep coming
    stopped = cell.cycles[start:]
    assert all(c.status == StatusCode.ROBOT_STOPPED and "PROTECTIVE_STOP" in c.message for c in stopped)
    for c in stopped:  # nothing to decelerate: a zero command where the arm is held, or nothing
        assert not c.publish or (not any(c.velocities) and np.allclose(c.positions, cell.q, atol=1e-9))
    cell.stage.robot_recovered()
    cell.held = False
    start = len(cell.cycles)
    cell.run(0.3)
    resumed = [c for c in cell.cycles[start:] if c.publish]
    first = np.array(resumed[0].positions)
    assert np.linalg.norm(cell.tip(first) - moving) < 0.002  # no jump over 2 mm from where it was held
    assert cell.cycles[-1].status != StatusCode.ROBOT_STOPPED
    assert np.linalg.norm(cell.tip() - moving) > 0.005  # and it moves again


def test_a_master_coming_back_does_not_lift_a_robot_stop(robot: Robot):
    cell = HeldCell(robot)
    cell.stage.suspend("the ROS master is gone")
    cell.stage.robot_stopped("the robot stopped: x")
    cell.stage.unsuspend()
    cell.run(0.05)
    assert cell.cycles[-1].status == StatusCode.ROBOT_STOPPED
    cell.stage.robot_recovered()
    cell.run(0.05)
    assert cell.cycles[-1].status != StatusCode.ROBOT_STOPPED


def test_a_recovery_while_the_master_is_lost_still_refuses_naming_the_master(robot: Robot):
    cell = HeldCell(robot)
    cell.stage.suspend("the ROS master is gone")
    cell.stage.robot_stopped("the robot stopped: x")
    cell.stage.robot_recovered()
    cell.run(0.05)
    last = cell.cycles[-1]
    assert last.status != StatusCode.ROBOT_STOPPED and "master is gone" in last.message, last.message
    assert not any(c.publish and any(c.velocities) for c in cell.cycles)  # held all along
