"""The sixth demonstration's flow (teach and replay) against a live stack, through its public ROS interface:
two compliant moves bring the tool over the L's first corner; contact_control's `~guide` on, teach's
`~record`; the simulated hand (the driver's `~push`) pushes the tool along each leg until it is nearly
there; `~stop` saves the program, guide off; teach's `~replay` action plays it back in free space at 1 x and
TEACH_FAST x, then pressing on Z, slowed to a top speed of TEACH_PRESS_VELOCITY. The StackClient records the
tool, the status and the sensor throughout.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import actionlib
import numpy as np
import rospy
from compliant_common.goal_call import GoalCall
from compliant_control_msgs.msg import (
    ReplayProgramAction,
    ReplayProgramFeedback,
    ReplayProgramGoal,
    ReplayProgramResult,
)
from compliant_control_msgs.srv import Guide, PushEEFRequest, RecordProgram
from std_srvs.srv import Trigger

from thesis_demos.analysis import Recording, Replayed
from thesis_demos.scenarios import (
    COMPLIANT_MOVE,
    TEACH_FAST,
    TEACH_PRESS_VELOCITY,
    TEACH_PUSH,
    AxisLaw,
    Scenario,
)
from thesis_demos.stack_client import StackClient

__all__ = ["PROGRAM", "TeachFlow"]

PROGRAM = "thesis_demos_teach_and_replay"  # the program's name in teach's programs_dir (overwritten)
POSITIONING_SPEED = 0.02  # [m/s] the compliant moves to the L's corner
# The hand lets go this long before the tool reaches the leg's end: the guided tool coasts on after the push
# (the force filter and the follower's deceleration), about its speed times this [s].
COAST_TIME = 0.12
REPLAY_TIMEOUT = 90.0  # [s] per replay (the pressed one: a 5 mm/s approach over some 5 cm, then the path)


class TeachFlow:
    """Runs teach and replay with a StackClient's connections and series."""

    def __init__(self, stack: StackClient, teach: str = "teach", timeout: float = 30.0) -> None:
        self.r = stack
        self._t0 = 0.0
        cc = stack.names.contact_control
        for service in (f"{teach}/record", f"{teach}/stop", f"{cc}/guide"):
            try:
                rospy.wait_for_service(service, timeout=timeout)
            except rospy.ROSException:
                raise RuntimeError(
                    f"no {service}: teach's program_server must run (control_stack's "
                    "with_teach:=true, the default)"
                ) from None
        self._record = rospy.ServiceProxy(f"{teach}/record", RecordProgram)
        self._stop_recording = rospy.ServiceProxy(f"{teach}/stop", Trigger)
        self._guide = rospy.ServiceProxy(f"{cc}/guide", Guide)
        self._replay = actionlib.ActionClient(f"{teach}/replay", ReplayProgramAction)
        if not self._replay.wait_for_server(rospy.Duration(timeout)):
            raise RuntimeError(f"no {teach}/replay action server")

    # --- the parts ---
    def _tip(self) -> np.ndarray:
        return self.r.tip()

    def _wait(self, predicate: Callable[[], object], timeout: float, what: str) -> None:
        self.r.wait(predicate, timeout, what)

    def _move_along(self, axis: int, distance: float) -> None:
        """A compliant move of `distance` [m] along base axis `axis`, ended by its max path deviation."""
        if abs(distance) < 0.002:
            return
        name = "xyz"[axis]
        law = AxisLaw(
            COMPLIANT_MOVE, velocity=math.copysign(POSITIONING_SPEED, distance), max_travel=abs(distance)
        )
        self.r.send(
            Scenario(name="teach_and_replay: to the corner", title="", laws={name: law}), {name: law}
        )
        self._wait(lambda: self.r.move_state()[0], 5.0, f"the move along {name} to start")
        self._wait(
            lambda: not self.r.move_state()[0],
            10.0 + 2 * abs(distance) / POSITIONING_SPEED,
            f"the move along {name} to end",
        )
        ended = self.r.move_state()[1].get(name)
        if ended != 2:  # MAX_TRAVEL
            raise RuntimeError(
                f"the move to the L's corner along {name} ended by condition {ended}, not by its "
                "travel (see contact_control's ~status)"
            )
        self._wait(self.r.still, 10.0, "the tool to rest at the corner")

    def _push_leg(self, axis: int, leg: float) -> None:
        """The hand pushes along `axis` with TEACH_PUSH until the tool is about `leg` [m] from its start."""
        start = self._tip()
        request = PushEEFRequest(duration=10.0)
        setattr(request.wrench.force, "xyz"[axis], math.copysign(TEACH_PUSH, leg))
        answer = self.r.push(request)
        if not answer.success:
            raise RuntimeError(f"the driver refused the push: {answer.message}")
        deadline = time.monotonic() + 20.0  # a hang guard; the speed is measured in ROS time (simulated)
        previous, previous_t = self._tip(), self.r.now()
        speed = 0.0
        while time.monotonic() < deadline:
            time.sleep(0.01)  # polling (a ROS sleep would hang on a stopped simulated clock)
            tip, now = self._tip(), self.r.now()
            speed = 0.7 * speed + 0.3 * abs(tip[axis] - previous[axis]) / max(now - previous_t, 1e-3)
            previous, previous_t = tip, now
            if abs(tip[axis] - start[axis]) >= abs(leg) - speed * COAST_TIME:
                break
        self.r.push(PushEEFRequest(duration=0.0))  # let go
        self._wait(lambda: not self.r.still(), 5.0, "the guided tool to move")
        self._wait(self.r.still, 15.0, "the guided tool to come to rest")

    def _replay_once(self, label: str, speed: float, press: bool, t0: float, target: float) -> Replayed:
        path_start = [math.nan]
        start = rospy.get_time() - t0

        def on_feedback(feedback: ReplayProgramFeedback) -> None:
            if feedback.state == "replaying" and math.isnan(path_start[0]):
                path_start[0] = rospy.get_time() - t0

        goal = ReplayProgramGoal(
            name=PROGRAM, speed=speed, press_axis="z" if press else "", press_force=target if press else 0.0
        )
        call: GoalCall[ReplayProgramFeedback, ReplayProgramResult] = GoalCall(self._replay, goal, on_feedback)
        if not call.wait(REPLAY_TIMEOUT):
            call.cancel()
            call.wait(10.0)
            result = call.result()
            message = f"no result within {REPLAY_TIMEOUT:g} s" + (f" ({result.message})" if result else "")
            return Replayed(label, speed, press, False, message, math.nan, math.nan, start=start)
        result = call.result()
        if result is None:  # not after a finished wait; for the type checker
            return Replayed(label, speed, press, False, "no result", math.nan, math.nan, start=start)
        print(f"  {label}: {result.message}", flush=True)
        return Replayed(
            label,
            speed,
            press,
            result.success,
            result.message,
            result.path_error_rms,
            result.path_error_max,
            result.force_mean,
            result.force_min,
            result.force_max,
            start=start,
            path_start=path_start[0],
            end=rospy.get_time() - t0,
        )

    def _top_speed(self, start: float, end: float) -> float:
        """The tool's top speed [m/s] between `start` and `end` (recording time), over 50 ms differences."""
        t, p = self.r.pose.arrays(self._t0)
        keep = (t >= start) & (t <= end)
        t, p = t[keep], p[keep]
        step = max(1, int(0.05 / max(float(np.median(np.diff(t))), 1e-4))) if len(t) > 2 else 1
        if len(t) <= step:
            return 0.0
        return float(np.max(np.linalg.norm(p[step:] - p[:-step], axis=1) / (t[step:] - t[:-step])))

    # --- the whole ---
    def run(self, scenario: Scenario, sensor_frame: str) -> Recording:
        assert scenario.teach is not None
        r = self.r
        baseline_t = r.prepare(sensor_frame)
        t0 = self._t0 = rospy.get_time()
        corner, legs = scenario.teach.corner, scenario.teach.legs
        self._move_along(0, corner[0])
        self._move_along(1, corner[1])
        guide = self._guide(enable=True, axes=[])
        if not guide.success:
            raise RuntimeError(f"hand-guiding refused: {guide.message}")
        replays: list[Replayed] = []
        try:
            record = self._record(name=PROGRAM, overwrite=True, keep_bag=False)
            if not record.success:
                raise RuntimeError(f"recording refused: {record.message}")
            taught_from = rospy.get_time() - t0
            self._push_leg(0, legs[0])
            self._push_leg(1, legs[1])
            taught = (taught_from, rospy.get_time() - t0)
            saved = self._stop_recording()
            if not saved.success:
                raise RuntimeError(f"saving the program failed: {saved.message}")
            print(f"  taught: {saved.message}", flush=True)
        finally:
            self._guide(enable=False, axes=[])
        slow = min(1.0, TEACH_PRESS_VELOCITY / max(self._top_speed(*taught), 1e-3))
        for label, speed, press in (
            ("free space 1x", 1.0, False),
            (f"free space {TEACH_FAST:g}x", TEACH_FAST, False),
            (f"pressing {scenario.press_force:g} N at {slow:.2g}x", slow, True),
        ):
            replayed = self._replay_once(label, speed, press, t0, scenario.press_force)
            replays.append(replayed)
            if not replayed.success:
                break  # the arm may still be moving away: the next replay would be refused
        _, ends = r.move_state()
        recording = r.recording(t0, baseline_t, ends, None)
        recording.taught = taught
        recording.replays = replays
        return recording
