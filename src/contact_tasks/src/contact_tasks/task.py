"""A contact task as data: named steps, each with laws, an optional motion pattern and exits (no ROS here).

Each section of a task file is a frozen dataclass declared with `compliant_common.schema.param`, so the file
is checked key by key with units and ranges, and the README's task-file tables are generated from here
(`make param-tables`). `task_file.load_task` builds a `Task` from YAML; `run.TaskRun` carries it out.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from compliant_common.errors import StackError
from compliant_common.schema import param, schema_of
from jog_arm.body_regions import OFF, REGIONS

__all__ = [
    "AXIS_NAMES",
    "EXIT_KINDS",
    "EXIT_SCHEMA",
    "LAW_SCHEMA",
    "PATTERN_KINDS",
    "PATTERN_SCHEMA",
    "RETRACT_SCHEMA",
    "STEP_SCHEMA",
    "TASK_SCHEMA",
    "Exit",
    "Law",
    "Pattern",
    "Retract",
    "Step",
    "Task",
    "TaskError",
]

AXIS_NAMES = ("x", "y", "z", "rx", "ry", "rz")
#: What ends a step (see `Exit`).
EXIT_KINDS = ("touch", "release", "move_ended", "force", "travel", "depth", "timeout", "pattern_done")
PATTERN_KINDS = ("none", "line", "spiral", "lissajous", "wiggle", "path")
_LAW_KINDS = ("none", "follower", "spring", "compliant_move", "force_tracking", "path", "normal")
_ACTIONS = ("stop", "move_away", "gravity_compensation")
_SIGNED_AXES = (*AXIS_NAMES, *(f"-{a}" for a in AXIS_NAMES[:3]))


class TaskError(StackError):
    """A task file that cannot be run, or a task that cannot start; the message names the file and key."""


@dataclass(frozen=True)
class Law:
    """One axis's law, in compliant_control_msgs/AxisLaw's words (contact_control's README, Laws)."""

    law: str = param("none", choices=_LAW_KINDS, doc="the law (AxisLaw's constants in lower case)")
    damping: float = param(0.0, unit="N/(m/s), Nm/(rad/s)", ge=0.0, doc="b")
    stiffness: float = param(0.0, unit="1/s", ge=0.0, doc="k of the spring; the path law's gain on its "
                             "error; the normal law's on its angle")
    velocity: float = param(0.0, unit="m/s, rad/s", doc="a compliant move's V_desired (signed); force "
                            "tracking's approach speed; a follower's or the normal law's speed cap")
    force_limit: float = param(0.0, unit="N, Nm", doc="|F| that ends the step's move (0: none; its sign "
                               "gives a compliant move's direction when velocity is 0)")
    max_travel: float = param(0.0, unit="m, rad", ge=0.0, doc="|d| that ends the step's move (0: none); the "
                              "path law's largest error")
    exceeded_action: str = param("stop", choices=_ACTIONS, doc="what the axis does when force_limit ends "
                                 "the move")
    target_force: float = param(0.0, unit="N, Nm", doc="force tracking: the force to hold as the sensor "
                                "reads it (pressing down on a table with 10 N is z 10)")


@dataclass(frozen=True)
class Pattern:
    """A motion superposed on the step's laws: a moving reference that the axes with the path law follow,
    in the plane (or about the axes) of the step's frame, starting from the tool's pose at the step's
    start."""

    type: str = param("none", choices=PATTERN_KINDS, doc="none, line, spiral (Archimedean), lissajous, "
                      "wiggle (tilts about RX and RY), path (given poses, not relative to the start)")
    speed: float = param(0.005, unit="m/s", gt=0.0, le=0.5, doc="line, spiral and path: speed along the "
                         "curve")
    axis: str = param("x", choices=_SIGNED_AXES, doc="line: its direction in the step's frame")
    distance: float = param(0.01, unit="m", gt=0.0, le=2.0, doc="line: its length")
    pitch: float = param(0.001, unit="m", gt=0.0, le=0.1, doc="spiral: radial distance between turns")
    max_radius: float = param(0.005, unit="m", gt=0.0, le=0.5, doc="spiral: where it ends (pattern_done)")
    amplitude: tuple[float, ...] = param((0.002, 0.002), type="floats", length=2, ge=0.0, le=0.5,
                                         unit="m or rad", doc="lissajous: (x, y) [m]; wiggle: (rx, ry) [rad]")
    frequency: tuple[float, ...] = param((0.5, 0.7), type="floats", length=2, gt=0.0, le=5.0, unit="Hz",
                                         doc="lissajous and wiggle: (x, y) / (rx, ry)")
    duration: float = param(10.0, unit="s", gt=0.0, doc="lissajous and wiggle: where they end (pattern_done)")
    poses: tuple[tuple[float, ...], ...] = param(
        (), type="any", unit="m, quaternion",
        doc="path: the tool tip's poses [x, y, z, qx, qy, qz, qw] in contact_control's fixed frame, z along "
        "the tool's axis into the part (README, Paths at a force)")
    forces: tuple[float, ...] = param((), type="floats", unit="N",
                                      doc="path: the force-tracking axis's target per segment (empty: the "
                                      "law's own)")
    angular_speed: float = param(0.2, unit="rad/s", gt=0.0, le=2.0,
                                 doc="path: the fastest turn between poses")
    ramp: float = param(0.5, unit="s", ge=0.0, le=10.0, doc="path: the time to speed up at its start and to "
                        "slow down at its end")


@dataclass(frozen=True)
class Exit:
    """When a step ends, and what comes next: exactly one of `next`, `succeed`, `fail`."""

    when: str = param("timeout", choices=EXIT_KINDS, doc="touch / release (contact_control's events), "
                      "move_ended (contact_control ended the step's move: a force limit, max travel, ...), "
                      "force (a force or torque along `axis`), travel (along `axis` since the step began), "
                      "depth (past the touch point along the approach), timeout, pattern_done")
    axis: str = param("z", choices=AXIS_NAMES, doc="force, travel: the axis (rx..rz: torque [Nm], rotation "
                      "[rad])")
    above: float | None = param(None, type="float", optional=True, unit="N, Nm, m, rad",
                                doc="force, travel, depth: true when the value is above this")
    below: float | None = param(None, type="float", optional=True, unit="N, Nm, m, rad",
                                doc="force, travel, depth: true when the value is below this")
    for_: float = param(0.0, unit="s", ge=0.0, key="for", doc="force, travel, depth: for this long")
    after: float = param(10.0, unit="s", gt=0.0, doc="timeout: the step's time")
    next: str = param("", doc="the step that follows")
    succeed: str = param("", doc="the task ends SUCCEEDED, with this reason")
    fail: str = param("", doc="the task ends FAILED, with this reason (then the on-failure step)")


@dataclass(frozen=True)
class Retract:
    """The built-in on-failure step: a compliant move back along the approach, the other translations
    compliant (followers), until `distance` or `timeout`."""

    distance: float = param(0.02, unit="m", gt=0.0, le=0.5, doc="how far back along the approach")
    speed: float = param(0.01, unit="m/s", gt=0.0, le=0.25, doc="how fast")
    damping: float = param(2000.0, unit="N/(m/s)", gt=0.0, doc="b of the move and of the followers")
    force_limit: float = param(20.0, unit="N", gt=0.0,
                               doc="|F| that stops the retract (contact_control refuses one above its global "
                               "limit)")
    timeout: float = param(10.0, unit="s", gt=0.0, doc="the retract ends after this long")


@dataclass(frozen=True)
class Step:
    """One step: the laws per axis (the axes left out do not move), a pattern, the exits in order (the first
    that holds is taken)."""

    laws: dict[str, Law] = field(default_factory=dict)
    pattern: Pattern = field(default_factory=Pattern)
    frame: str = "tool"
    exits: tuple[Exit, ...] = ()
    law_frame: str = "fixed"


@dataclass(frozen=True)
class _StepKeys:
    laws: dict[str, object] = param({}, type="mapping", doc="axis (x .. rz) -> law (below); axes left out do "
                                    "not move")
    pattern: dict[str, object] = param({}, type="mapping", doc="a motion superposed on the laws (below)")
    frame: str = param("tool", choices=("tool", "fixed"), doc="the pattern's axes: the tool's at the step's "
                       "start, or contact_control's fixed frame")
    exits: list[object] = param([], type="any", doc="a list of exits (below), the first that holds is taken")
    law_frame: str = param("fixed",
                           doc="the laws' axes: `fixed`, contact_control's control_frame; `tool`, the tool's "
                           "(its eef_frame, turning with it: pressing along the tool's axis on a curved "
                           "part); `tool_at_start`, the tool's as they were when the step began (they do not "
                           "turn when the tool does); any other name, that tf frame as contact_control looks "
                           "it up (a part's frame from a fixture or a camera)")


@dataclass(frozen=True)
class Task:
    """A task: its steps by name (in file order), where it starts, its limits and what it does on failure."""

    name: str
    steps: dict[str, Step]
    start: str
    approach: str = "-z"
    approach_frame: str = "fixed"
    surface: float | None = None
    force_ceiling: float = 25.0
    torque_ceiling: float = 2.0
    time_limit: float = 0.0
    on_failure: str = ""
    retract: Retract = field(default_factory=Retract)
    description: str = ""
    body_region: str = ""


@dataclass(frozen=True)
class _TaskKeys:
    task: str = param("", doc="the task's name (required)")
    description: str = param("", doc="what it does, in words")
    start: str = param("", doc="the first step (default: the first in `steps`)")
    approach: str = param("-z", choices=("x", "y", "z", "-x", "-y", "-z"), doc="the direction the tool moves "
                          "into the part, in contact_control's control frame (depth is measured along it)")
    approach_frame: str = param("fixed", choices=("fixed", "tool"),
                                doc="`approach` is along contact_control's control frame, or the tool's "
                                "(as it was at the task's start; the retract then runs along the tool's "
                                "axes)")
    surface: float | None = param(
        None, type="float", optional=True, ge=0.0, unit="m",
        doc="the part's nominal surface this far along `approach` from the tool at the task's start: depth "
        "counts from it until the first touch (a peg that meets the hole on its way in never touches)",
    )
    force_ceiling: float = param(25.0, unit="N", gt=0.0, doc="|F| above this fails the task at once")
    torque_ceiling: float = param(2.0, unit="Nm", gt=0.0, doc="|T| above this fails the task at once")
    time_limit: float = param(0.0, unit="s", ge=0.0, doc="the task fails when it has run this long (0: no "
                              "limit); it bounds steps that lead back to each other")
    on_failure: str = param("", doc="a step run when the task fails (default: the built-in retract)")
    body_region: str = param(
        "", choices=("", OFF, *REGIONS),
        doc="the body region of ISO/TS 15066 jog_arm caps the speed and releases clamps for while the task "
        "runs (its `collaborative_region`, set back afterwards); empty: the robot's own",
    )
    retract: dict[str, object] = param({}, type="mapping", doc="the built-in retract's settings (below)")
    steps: dict[str, object] = param({}, type="mapping", doc="step name -> step (below), in order")


TASK_SCHEMA = schema_of(_TaskKeys)
STEP_SCHEMA = schema_of(_StepKeys)
LAW_SCHEMA = schema_of(Law)
PATTERN_SCHEMA = schema_of(Pattern)
EXIT_SCHEMA = schema_of(Exit)
RETRACT_SCHEMA = schema_of(Retract)
