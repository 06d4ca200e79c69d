"""/diagnostics: the health reports' levels (pure), and on an emulated UR cell every node of ours
reporting, contact_control OK while the sensor is fresh and ERROR with the reason within 1 s of stopping the
driver, as `rosrun compliant_common show_diagnostics` prints it."""

from __future__ import annotations

import os
import subprocess
import time

import pytest
from compliant_common.diagnostics import ERROR, OK, WARN, Report, rate_check, summary
from contact_control.axes import SAFETY_OK, SAFETY_STALE, SAFETY_ZEROING
from contact_control.cycle import CycleResult
from contact_control.health import contact_health
from contact_control.noise_floor import NoiseFloor
from contact_control.params import load_settings

SETTINGS = load_settings({})


def _result(safety: int, move: bool = False) -> CycleResult:
    laws = [0, 0, 4, 0, 0, 0] if move else [0] * 6
    return CycleResult(1.0, [0.0] * 6, [0.0] * 6, [0.0] * 6, laws, [0] * 6, move, safety, "", -1, 3)


def _health(safety: int = SAFETY_OK, message: str = "", period: float | None = 0.002,
            drift: tuple[float, ...] | None = None, master: str = "", move: bool = False,
            robot_stop: str = "") -> Report:
    floor = NoiseFloor((0.2,) * 6, 500.0, 500, (0.05,) * 6)
    return contact_health("/contact_control_node", SETTINGS, _result(safety, move), message, period, 0.002,
                          0.1, floor, drift, master, False, robot_stop)


def test_levels_follow_the_documented_thresholds():
    assert rate_check(495.0, 500.0, "wrench") == (OK, "")
    assert rate_check(300.0, 500.0, "wrench")[0] == WARN and rate_check(100.0, 500.0, "wrench")[0] == ERROR
    assert "not measured" in rate_check(None, 500.0, "wrench")[1]
    fine = _health()
    assert fine.level == OK and fine.message == "idle, sensor fresh"
    assert _health(move=True).message == "move 3 running" and ("move", "move 3: z=force_tracking") in \
        _health(move=True).values
    stale = _health(SAFETY_STALE, "no wrench for 0.312 s (wrench_timeout 0.1 s)")
    assert stale.level == ERROR and stale.message.startswith("no wrench for 0.312 s")
    assert _health(SAFETY_ZEROING, "zeroing the sensor").level == WARN
    slow = _health(period=1.0 / 92.0)  # a 92 Hz sensor where 500 Hz was configured
    assert slow.level == ERROR and "wrench at 92 Hz, expected 500 Hz" in slow.message
    drifted = _health(drift=(0.0, 0.0, 1.5, 0.0, 0.0, 0.0))  # 7.5 raw noise stds
    assert drifted.level == WARN and "zero drifted 1.5 N" in drifted.message
    assert _health(drift=(0.0, 0.0, 0.5, 0.0, 0.0, 0.0)).level == OK
    lost = _health(master="ROS master lost: connection refused")
    assert lost.level == ERROR and "ROS master lost" in lost.message
    stopped = _health(robot_stop="the robot stopped: x/safety_mode reads PROTECTIVE_STOP (3)")
    assert stopped.level == WARN and stopped.message.startswith("the robot stopped: x/safety_mode reads "
                                                                "PROTECTIVE_STOP (3): requests refused")
    assert ("robot", "the robot stopped: x/safety_mode reads PROTECTIVE_STOP (3)") in stopped.values
    assert ("robot", "running (no stop reported by jog_arm)") in fine.values
    text = summary([(OK, "/b", "fine", []), (ERROR, "/a", "broken", [("k", "v")])], detail=True)
    assert text.splitlines() == ["[ ERROR ] /a - broken", "    - k: v", "[ OK ] /b - fine"]


pytest.importorskip("compliant_control_msgs.msg", reason="needs devel/setup.bash (make test sources it)")


def test_killing_the_driver_shows_error_with_the_reason_within_a_second(ros_node):
    """As on a cell: the (emulated) ur_robot_driver in one launch, the robot package's hardware.launch in
    another; the driver's launch is stopped (in sim.launch the driver is `required`: its death ends all)."""
    from diagnostic_msgs.msg import DiagnosticArray
    from harness.launch import run_launch
    from harness.waiting import Collector, wait_until

    driver_args = {"robot_package": "ur5_custom", "profile": "ur_robot_driver"}
    with run_launch("mujoco_driver", "emulated_robot.launch", driver_args) as driver, \
            run_launch("ur5_custom", "hardware.launch") as stack:
        diagnostics = Collector("/diagnostics", DiagnosticArray)
        try:

            def contact(level: int | None = None) -> list[tuple[float, object]]:
                return [(t, s) for t, m in diagnostics.timed() for s in m.status
                        if s.name == "/contact_control_node" and (level is None or s.level == level)]

            wait_until(lambda: contact(OK), 40, "contact_control OK on /diagnostics")
            _, ok = contact(OK)[-1]
            values = {kv.key: kv.value for kv in ok.values}
            assert float(values["wrench rate [Hz]"]) == pytest.approx(125.0, rel=0.1), values  # CB3's
            # Before the driver's first wrench the node was stale: shown as the last fault, with its age.
            assert values["safety"] == "ok", values
            assert values["last fault"] == "none" or " s ago: " in values["last fault"], values
            shown = subprocess.run(["rosrun", "compliant_common", "show_diagnostics", "--detail"],
                                   capture_output=True, text=True, timeout=30, check=False)
            expected = "[ OK ] /contact_control_node - idle, sensor fresh"
            assert expected in shown.stdout, shown.stdout + shown.stderr
            assert "    - wrench rate [Hz]: " in shown.stdout
            ours = ("/jog_arm_server", "/mujoco_driver", "/named_poses", "/teach", "/task_server")
            for node in ours:  # every node of ours
                assert f"] {node} - " in shown.stdout, shown.stdout
            killed = time.monotonic()
            driver.stop()
            wait_until(lambda: [t for t, _ in contact(ERROR) if t > killed], 5, "ERROR on /diagnostics")
            t, error = next((t, s) for t, s in contact(ERROR) if t > killed)
            print(f"\nERROR {t - killed:.2f} s after stopping the driver: {error.message}")
            assert t - killed < 1.0 and error.message.startswith("no wrench for"), error.message
            shown = subprocess.run(["rosrun", "compliant_common", "show_diagnostics", "--level", "2"],
                                   capture_output=True, text=True, timeout=30, check=False)
            assert "[ ERROR ] /contact_control_node - no wrench for" in shown.stdout, shown.stdout
            assert "[ ERROR ] /jog_arm_server - " in shown.stdout, shown.stdout  # no joint states either
        finally:
            diagnostics.close()
        stack.stop()


def test_jog_arm_and_driver_levels():
    from jog_arm.health import jog_health
    from jog_arm.stage import JogCycle
    from jog_arm.status import StatusCode
    from mujoco_driver.health import driver_health

    def cycle(status: StatusCode, message: str = "", cap: float = float("inf")) -> JogCycle:
        return JogCycle(1.0, True, (), (), (), status, message, 12.0, 0.5, cap, False)

    assert jog_health("/j", None, None, 500.0, "").level == ERROR
    assert jog_health("/j", cycle(StatusCode.STALE_COMMAND), 500.0, 500.0, "").message == "idle (no command)"
    halt = jog_health("/j", cycle(StatusCode.HALT_FOR_SINGULARITY, "condition 40 > 30"), 480.0, 500.0, "")
    assert halt.level == ERROR and halt.message == "condition 40 > 30"
    assert jog_health("/j", cycle(StatusCode.JOINT_VELOCITY_SCALED, "scaled"), None, 500.0, "").level == WARN
    assert jog_health("/j", cycle(StatusCode.NO_WARNING), 500.0, 500.0, "ROS master lost").level == ERROR
    capped = jog_health("/j", cycle(StatusCode.COLLABORATIVE_SPEED_CAP, "capped", 0.157), 500.0, 500.0, "",
                        "face")
    assert capped.level == OK and capped.message == "capped"  # a limit working, not a fault
    assert ("speed cap [m/s]", "0.157") in capped.values
    assert ("body region (ISO/TS 15066)", "face") in capped.values
    assert driver_health("/d", 1.0, 1.0, 0.0, {}, 3.0, "velocity").level == OK
    slow = driver_health("/d", 0.4, 1.0, 2.5, {}, 3.0, "velocity")
    assert slow.level == ERROR and "real-time factor at 0.4, expected 1" in slow.message
    assert driver_health("/d", 0.2, 0.0, 0.0, {}, 3.0, "velocity").level == OK  # as fast as possible
    assert driver_health("/d", 1.0, 1.0, 0.0, {"mjWARN_BADQACC": 2}, 3.0, "position").level == WARN
    moving = driver_health("/d", 1.0, 1.0, 0.0, {}, 3.0, "velocity", (0.0002, 0.0004))
    assert ("end to end p50 / p99 [ms]", "0.20 / 0.40") in moving.values


def test_show_diagnostics_says_when_nothing_publishes(ros_node):
    run = subprocess.run(["rosrun", "compliant_common", "show_diagnostics", "--wait", "0.3"],
                         capture_output=True, text=True, timeout=30, check=False, env=dict(os.environ))
    assert run.returncode == 1 and "nothing on /diagnostics within 0.3 s" in run.stdout
