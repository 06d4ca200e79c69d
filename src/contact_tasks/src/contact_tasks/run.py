"""Carrying out a task: which step runs, what contact_control is asked, when the task ends (no ROS here).

`TaskRun` is fed an `Observation` each cycle (what contact_control's ~status, ~events and tf say) and answers
a `Command` (laws to set when a step begins, the path reference to stream, stop at the end). It holds nothing
of contact_control's internals: the node turns commands into ConfigureLaws calls and ~path_reference
messages, and the tests feed it from the pure controller in a closed loop. See the package README.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from compliant_common.typedefs import FloatArray
from contact_control.frames import matrix_quaternion, quaternion_matrix
from contact_control.travel import rotation_vector

from contact_tasks.path import PathPoint, PosePath
from contact_tasks.patterns import PatternPoint, evaluate
from contact_tasks.task import AXIS_NAMES, Exit, Law, Pattern, Step, Task
from contact_tasks.task_file import laws_request

__all__ = ["CANCELLED", "FAILED", "RUNNING", "SUCCEEDED", "TOOL_AT_START", "Command", "Observation",
           "TaskRun"]

RUNNING, SUCCEEDED, FAILED, CANCELLED = "running", "succeeded", "failed", "cancelled"
ARRIVED = 0.002  # [m] a path's end is reached this close to its last pose, across the tool's axis
_RETRACT = "retract"  # the built-in on-failure step's name in results
TOOL_AT_START = "tool_at_start"  # law_frame: the tool's axes where the step began, not turning after
_DIRECTIONS = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Observation:
    """What the executor knows at time `t` [s].

    Attributes:
        tool: the end effector's 4x4 pose in contact_control's fixed frame.
        wrench: contact_control's preprocessed wrench in its control frame (fx, fy, fz, tx, ty, tz).
        move_active: the current step's move runs (a status from after its laws were set; True until one
            came).
        move_message: contact_control's status message (why the move ended).
        touched, released: a touch / release event came since the previous observation.
        robot_stop: why the robot stopped by itself (jog_arm's ``~robot_stop``), "" while it runs.
    """

    t: float
    tool: FloatArray
    wrench: Sequence[float] = (0.0,) * 6
    move_active: bool = True
    move_message: str = ""
    touched: bool = False
    released: bool = False
    robot_stop: str = ""


Position = tuple[float, float, float]
Orientation = tuple[float, float, float, float]  # a quaternion (x, y, z, w)


@dataclass(frozen=True)
class Reference:
    """The path law's reference in the fixed frame: position [m], quaternion (x, y, z, w), twist, and its
    horizon: (position, quaternion) `horizon_step`, 2 `horizon_step`, ... [s] on (contact_control follows it
    when the stream is late)."""

    position: tuple[float, float, float]
    quaternion: tuple[float, float, float, float]
    twist: tuple[float, float, float, float, float, float]
    horizon: tuple[tuple[Position, Orientation], ...] = ()
    horizon_step: float = 0.0


@dataclass(frozen=True)
class Command:
    """What to do this cycle.

    Attributes:
        laws: a ConfigureLaws-shaped request to send now (a step began; send `reference` first), or None.
        restart: stop the running move before sending `laws`: contact_control carries an axis that keeps
            its law type on from the running move (its travel too), and a step's travel counts from its start.
        reference: the path reference to publish now, or None (the step has no path law).
        stop: stop contact_control's move (the task ended).
        frame_pose: the tool's 4x4 pose (fixed frame) to put on tf as `start_frame` before `laws` are sent
            (a step whose laws act along the tool's axes at its start), or None.
        outcome: RUNNING, SUCCEEDED, FAILED or CANCELLED; reason: why it ended.
    """

    step: str
    laws: object | None = None
    restart: bool = False
    reference: Reference | None = None
    stop: bool = False
    outcome: str = RUNNING
    reason: str = ""
    frame_pose: FloatArray | None = None


@dataclass
class Result:
    """How the task went: the outcome and reason, time per step [s], the peaks, where the tool ended."""

    outcome: str = RUNNING
    reason: str = ""
    step_times: dict[str, float] = field(default_factory=dict)
    peak_force: float = 0.0
    peak_torque: float = 0.0
    end_pose: FloatArray | None = None


class TaskRun:
    """One run of a task; `start`, then `update` every cycle until the outcome is not RUNNING."""

    def __init__(self, task: Task, horizon: float = 0.0, horizon_step: float = 0.02,
                 tool_frame: str = "tool_tip", start_frame: str = "task_step_start") -> None:
        """`tool_frame`: contact_control's eef_frame, the axes of a step with `law_frame: tool`;
        `start_frame`: the tf frame the node puts where the tool is when a step with `law_frame:
        tool_at_start` begins (another name is a tf frame, passed on as it is)."""
        self.task = task
        self.tool_frame = tool_frame
        self.start_frame = start_frame
        self._ahead = (round(horizon / horizon_step) if horizon > 0.0 else 0, horizon_step)
        self.result = Result()
        self.step_name = ""
        self.depth = math.nan  # past the touch point along the approach [m]
        self.search_radius = 0.0  # the pattern's distance from its start [m]
        self._step: Step | None = None
        self._step_t = 0.0
        self._start_pose = np.eye(4)
        self._frame = np.eye(3)
        self._touch: FloatArray | None = None
        self._origin: FloatArray | None = None  # the tool's position at the task's start
        self._started = 0.0  # [s] obs.t at the task's start
        self._since: dict[int, float] = {}  # exit index -> when its threshold began to hold
        self._failing = ""  # the task's failure reason while its on-failure step runs
        self._path: PosePath | None = None  # a path pattern's, while its step runs
        self._force = math.nan  # the target a path's segment set (nan: the step's own)
        #: Where a path pattern's reference is, while its step runs (None: no path).
        self.path_point: PathPoint | None = None
        sign = -1.0 if task.approach.startswith("-") else 1.0
        self._approach = np.zeros(3)
        self._approach[_DIRECTIONS[task.approach.lstrip("-")]] = sign

    @property
    def running(self) -> bool:
        return self.result.outcome == RUNNING

    def start(self, obs: Observation) -> Command:
        """Begins the task's first step at `obs`."""
        if self.task.approach_frame == "tool":
            self._approach = obs.tool[:3, :3] @ self._approach
        self._origin = obs.tool[:3, 3].copy()
        self._started = obs.t
        return self._begin(self.task.start, self.task.steps[self.task.start], obs)

    def update(self, obs: Observation) -> Command:
        """One cycle: the task's ceilings, then the step's exits in order; the reference to stream."""
        if not self.running or self._step is None:
            return Command(self.step_name, outcome=self.result.outcome, reason=self.result.reason)
        if obs.robot_stop:  # the driver holds the arm: no step, not even the retract, can move it
            failing = f"{self._failing}; then " if self._failing else ""
            return self._end(FAILED, f"{failing}in step '{self.step_name}': {obs.robot_stop}", obs)
        force = math.sqrt(sum(f * f for f in obs.wrench[:3]))
        torque = math.sqrt(sum(f * f for f in obs.wrench[3:]))
        self.result.peak_force = max(self.result.peak_force, force)
        self.result.peak_torque = max(self.result.peak_torque, torque)
        if obs.touched and self._touch is None:
            self._touch = obs.tool[:3, 3].copy()
        if self._touch is not None:
            self.depth = float((obs.tool[:3, 3] - self._touch) @ self._approach)
        elif self.task.surface is not None and self._origin is not None:
            self.depth = float((obs.tool[:3, 3] - self._origin) @ self._approach) - self.task.surface
        task = self.task
        # The ceilings guard the task's own steps; the on-failure step backs off from a force that may still
        # be above them (its own force limit and contact_control's global limits guard it).
        if not self._failing and (force > task.force_ceiling or torque > task.torque_ceiling):
            over = (f"|F| {force:.1f} N above the task's force ceiling {task.force_ceiling:g} N"
                    if force > task.force_ceiling else
                    f"|T| {torque:.2f} Nm above the task's torque ceiling {task.torque_ceiling:g} Nm")
            return self._fail(f"in step '{self.step_name}': {over}", obs)
        if not self._failing and 0.0 < task.time_limit < obs.t - self._started:
            return self._fail(f"in step '{self.step_name}': the task ran longer than its time limit "
                              f"{task.time_limit:g} s", obs)
        step_t = obs.t - self._step_t
        point = self._point(step_t, obs.tool)
        self.search_radius = point.radius
        for i, ex in enumerate(self._step.exits):
            if self._holds(i, ex, obs, step_t, point):
                return self._take(ex, obs, obs.move_message if ex.when == "move_ended" else "")
        return Command(self.step_name, laws=self._segment_laws(), reference=self._reference(point, step_t))

    def cancel(self, obs: Observation) -> Command:
        """The task is cancelled: stop the move."""
        return self._end(CANCELLED, f"cancelled in step '{self.step_name}'", obs)

    def refused(self, message: str, obs: Observation) -> Command:
        """contact_control refused the step's laws (they did not fit its limits): stop, FAILED."""
        reason = f"contact_control refused step '{self.step_name}': {message}"
        return self._end(FAILED, f"{self._failing}; then {reason}" if self._failing else reason, obs)

    # steps

    def _begin(self, name: str, step: Step, obs: Observation) -> Command:
        restart = self._step is not None and bool(self._step.laws)
        self._account(obs)
        self.step_name, self._step, self._step_t = name, step, obs.t
        self._start_pose = obs.tool.copy()
        self._frame = obs.tool[:3, :3].copy() if step.frame == "tool" else np.eye(3)
        self._since.clear()
        self.search_radius = 0.0
        self.result.step_times.setdefault(name, 0.0)
        pattern = step.pattern
        self._path = None
        if pattern.type == "path":
            self._path = PosePath(pattern.poses, pattern.speed, pattern.angular_speed, pattern.ramp)
        self.path_point, self._force = None, math.nan
        reference = self._reference(self._point(0.0, obs.tool), 0.0) if _has_path(step) else None
        laws = self._segment_laws() or laws_request(step.laws, self._law_frame(step))
        pose = obs.tool.copy() if step.law_frame == TOOL_AT_START else None
        return Command(name, laws=laws, restart=restart, reference=reference, frame_pose=pose)

    def _law_frame(self, step: Step) -> str:
        """ConfigureLaws' frame for the step: "" (control_frame), the tool's (turning with it, or as it was at
        the step's start), or the tf frame it names."""
        known = {"fixed": "", "tool": self.tool_frame, TOOL_AT_START: self.start_frame}
        return known.get(step.law_frame, step.law_frame)

    def _point(self, step_t: float, tool: FloatArray) -> PatternPoint:
        """The step's pattern at `step_t`; a path's also in `path_point`. A path is done once its reference
        ended and the tool has come within ARRIVED of its end across its axis (a part off its nominal place
        moves the end along the axis): give its step a timeout exit for a tool that never gets there."""
        assert self._step is not None
        if self._path is None:
            return evaluate(self._step.pattern, step_t)
        p = self.path_point = self._path.at(step_t)
        done = p.done
        if done:
            off = np.asarray(p.position) - tool[:3, 3]
            axis = tool[:3, 2]
            done = float(np.linalg.norm(off - (off @ axis) * axis)) <= ARRIVED
        return PatternPoint((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0,) * 6, done, p.arc)

    def _segment_laws(self) -> object | None:
        """The step's laws with the force of the path's segment when it changed (a bumpless change in
        contact_control: same laws, new target), else None."""
        step, point = self._step, self.path_point
        if step is None or point is None or not step.pattern.forces:
            return None
        force = step.pattern.forces[point.segment]
        if force == self._force:
            return None
        self._force = force
        laws = {a: replace(law, target_force=force) if law.law == "force_tracking" else law
                for a, law in step.laws.items()}
        return laws_request(laws, self._law_frame(step))

    def _take(self, ex: Exit, obs: Observation, why: str) -> Command:
        """Takes exit `ex`; `why`: contact_control's word on how the step's move ended (a failure says it)."""
        if ex.next:
            return self._begin(ex.next, self.task.steps[ex.next], obs)
        if self._failing:
            said = ex.fail or ex.succeed
            return self._end(FAILED, f"{self._failing} ({self.step_name}: {said})", obs)
        if ex.succeed:
            return self._end(SUCCEEDED, ex.succeed, obs)
        return self._fail(f"in step '{self.step_name}': {ex.fail}" + (f" ({why})" if why else ""), obs)

    def _fail(self, reason: str, obs: Observation) -> Command:
        """The task failed: its on-failure step (or the built-in retract) runs, then it ends FAILED."""
        self._failing = reason
        task = self.task
        if task.on_failure:
            return self._begin(task.on_failure, task.steps[task.on_failure], obs)
        return self._begin(_RETRACT, _retract_step(task), obs)

    def _end(self, outcome: str, reason: str, obs: Observation) -> Command:
        self._account(obs)
        self.result.outcome, self.result.reason = outcome, reason
        self.result.end_pose = obs.tool.copy()
        self._step = None
        return Command(self.step_name, stop=True, outcome=outcome, reason=reason)

    def _account(self, obs: Observation) -> None:
        if self._step is not None:
            times = self.result.step_times
            times[self.step_name] = times.get(self.step_name, 0.0) + obs.t - self._step_t
            self._step_t = obs.t

    # exits

    def _holds(self, i: int, ex: Exit, obs: Observation, step_t: float, point: PatternPoint) -> bool:
        when = ex.when
        if when == "timeout":
            return step_t >= ex.after
        if when == "touch":
            return obs.touched
        if when == "release":
            return obs.released
        if when == "move_ended":
            return bool(self._step and self._step.laws) and not obs.move_active
        if when == "pattern_done":
            return point.done
        value = self._value(ex, obs)
        if ex.above is not None:
            met = value > ex.above  # NaN (no touch point yet) is never above nor below
        else:
            met = ex.below is not None and value < ex.below
        if not met:
            self._since.pop(i, None)
            return False
        began = self._since.setdefault(i, obs.t)
        return obs.t - began >= ex.for_

    def _value(self, ex: Exit, obs: Observation) -> float:
        axis = AXIS_NAMES.index(ex.axis)
        if ex.when == "force":
            return float(obs.wrench[axis])
        if ex.when == "depth":
            return self.depth
        if axis < 3:  # travel along a fixed-frame axis since the step began
            return float(obs.tool[axis, 3] - self._start_pose[axis, 3])
        turned = obs.tool[:3, :3] @ self._start_pose[:3, :3].T
        return float(rotation_vector(turned.tolist())[axis - 3])

    # the reference

    def _reference(self, point: PatternPoint, step_t: float) -> Reference | None:
        """The reference at `point` (the pattern at `step_t` into the step) and its horizon."""
        if self._step is None or not _has_path(self._step):
            return None
        if self._path is not None:
            return self._path_reference(step_t)
        frame = self._frame
        linear = frame @ np.asarray(point.twist[:3])
        angular = frame @ np.asarray(point.twist[3:])
        count, step = self._ahead
        pattern = self._step.pattern
        horizon = tuple(self._pose(evaluate(pattern, step_t + j * step)) for j in range(1, count + 1))
        return Reference(
            *self._pose(point),
            (float(linear[0]), float(linear[1]), float(linear[2]),
             float(angular[0]), float(angular[1]), float(angular[2])),
            horizon, step if horizon else 0.0,
        )

    def _path_reference(self, step_t: float) -> Reference:
        """A path pattern's reference: its own poses (fixed frame), not offsets from the step's start."""
        assert self._path is not None
        p = self._path.at(step_t)
        count, step = self._ahead
        horizon = tuple((h.position, h.quaternion) for h in (self._path.at(step_t + j * step)
                                                              for j in range(1, count + 1)))
        return Reference(p.position, p.quaternion, p.twist, horizon, step if horizon else 0.0)

    def _pose(self, point: PatternPoint) -> tuple[Position, Orientation]:
        """The fixed frame's position and quaternion of a pattern point."""
        frame, start = self._frame, self._start_pose
        position = start[:3, 3] + frame @ np.asarray(point.offset)
        turn = np.asarray(quaternion_matrix(*_rotvec_quaternion(frame @ np.asarray(point.rotation))))
        x, y, z, w = matrix_quaternion((turn @ start[:3, :3]).tolist())
        return (float(position[0]), float(position[1]), float(position[2])), (float(x), float(y), float(z),
                                                                              float(w))


def _has_path(step: Step) -> bool:
    return any(law.law == "path" for law in step.laws.values())


def _retract_step(task: Task) -> Step:
    """Back along the approach at the retract's speed for its distance, the other translations followers."""
    r = task.retract
    back = task.approach.lstrip("-")
    sign = 1.0 if task.approach.startswith("-") else -1.0
    laws = {a: Law(law="follower", damping=r.damping) for a in ("x", "y", "z") if a != back}
    laws[back] = Law(law="compliant_move", damping=r.damping, velocity=sign * r.speed,
                     force_limit=r.force_limit, max_travel=r.distance)
    exits = (Exit(when="move_ended", fail="retracted"),
             Exit(when="timeout", after=r.timeout, fail=f"the retract did not end within {r.timeout:g} s"))
    return Step(laws=laws, pattern=Pattern(), frame="fixed", exits=exits, law_frame=task.approach_frame)


def _rotvec_quaternion(v: FloatArray) -> tuple[float, float, float, float]:
    angle = float(np.linalg.norm(v))
    if angle < 1e-12:
        return (0.0, 0.0, 0.0, 1.0)
    k = v * (math.sin(angle / 2.0) / angle)
    return (float(k[0]), float(k[1]), float(k[2]), math.cos(angle / 2.0))
