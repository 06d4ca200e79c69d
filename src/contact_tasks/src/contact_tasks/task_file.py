"""Task files: YAML in, a checked `Task` out, or a `TaskError` naming the file, the key and why (no ROS here).

Checked at load, before anything moves: every key against its declaration (units, ranges, did-you-mean),
each step's laws as contact_control would check them, exits (one outcome each, a threshold where one is
needed), step names (unknown ones with the closest, steps no exit reaches, steps without an exit) and limits
that could never act (a force exit or limit above the task's ceiling).
"""

from __future__ import annotations

import difflib
import pathlib
import re
from collections.abc import Mapping
from dataclasses import replace

import yaml
from compliant_common.schema import Schema, SchemaError
from contact_control.axes import EXCEEDED_ACTION_NAMES, LAW_NAMES
from contact_control.request import RequestError, empty_laws_request, validate_laws_request

from contact_tasks.path import PosePath
from contact_tasks.task import (
    AXIS_NAMES,
    EXIT_SCHEMA,
    LAW_SCHEMA,
    PATTERN_SCHEMA,
    RETRACT_SCHEMA,
    STEP_SCHEMA,
    TASK_SCHEMA,
    Exit,
    Law,
    Pattern,
    Retract,
    Step,
    Task,
    TaskError,
)

__all__ = ["laws_request", "load_task", "load_task_file", "merged", "parse_task"]

_LAW_CODES = {name: code for code, name in LAW_NAMES.items()}
_ACTION_CODES = {name: code for code, name in EXCEEDED_ACTION_NAMES.items()}
# The pattern keys each type reads; a key of another type is refused (it would silently do nothing).
_PATTERN_KEYS = {
    "none": (),
    "line": ("speed", "axis", "distance"),
    "spiral": ("speed", "pitch", "max_radius"),
    "lissajous": ("amplitude", "frequency", "duration"),
    "wiggle": ("amplitude", "frequency", "duration"),
    "path": ("poses", "speed", "forces", "angular_speed", "ramp"),
}
_THRESHOLD_EXITS = ("force", "travel", "depth")
_TF_NAME = re.compile(r"[A-Za-z0-9_./-]+")


def load_task_file(path: str | pathlib.Path, overrides: str = "") -> Task:
    """The task in a YAML file (`overrides`: see `load_task`).

    Raises:
        TaskError: unreadable, not YAML, or not a valid task: "<file>: <key>: <why>".
    """
    path = pathlib.Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise TaskError(f"{path}: cannot read the task file: {err.strerror}") from None
    return load_task(text, str(path), overrides)


def load_task(text: str, source: str = "<task>", overrides: str = "") -> Task:
    """The task in YAML `text`; `source` names it in errors (a file name, or "<goal>" for an inline one).
    `overrides`: a YAML mapping merged over it key by key before it is checked (`{surface: 0.05}`,
    `{steps: {search: {pattern: {pitch: 0.001}}}}`)."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise TaskError(f"{source}: not YAML: {err}") from None
    if overrides.strip():
        try:
            extra = yaml.safe_load(overrides)
        except yaml.YAMLError as err:
            raise TaskError(f"{source}: the overrides are not YAML: {err}") from None
        if not isinstance(extra, Mapping) or not isinstance(data, Mapping):
            raise TaskError(f"{source}: the overrides must be a mapping of the task's keys, got {extra!r}")
        data = merged(data, extra)
    return parse_task(data, source)


def merged(base: Mapping[str, object], extra: Mapping[str, object]) -> dict[str, object]:
    """`base` with `extra` merged in: mappings key by key, anything else replaced."""
    out = dict(base)
    for key, value in extra.items():
        old = out.get(key)
        out[key] = merged(old, value) if isinstance(old, Mapping) and isinstance(value, Mapping) else value
    return out


def parse_task(data: object, source: str = "<task>") -> Task:
    """The task in an already parsed YAML document (a mapping)."""
    try:
        return _Parser(source).task(data)
    except _RefusedError as err:
        raise TaskError(f"{source}: {err}") from None


class _RefusedError(TaskError):
    """One problem, with its key path, before the file's name is put in front (`parse_task`)."""


def _load(schema: Schema, data: object, where: str) -> dict[str, object]:
    if not isinstance(data, Mapping):
        raise _RefusedError(f"{where.rstrip('.') or 'the file'}: expected a mapping of keys, got {data!r}")
    try:
        return schema.load({str(k): v for k, v in data.items()}, prefix=where)
    except SchemaError as err:
        raise _RefusedError(err.named(where)) from None


def _closest(name: str, known: list[str]) -> str:
    close = difflib.get_close_matches(name, known, n=1, cutoff=0.5)
    return f"did you mean {close[0]!r}?" if close else f"the steps are {', '.join(known)}"


class _Parser:
    def __init__(self, source: str) -> None:
        self.source = source

    def task(self, data: object) -> Task:
        keys = _load(TASK_SCHEMA, data, "")
        raw_steps = keys.get("steps") or {}
        if not raw_steps:
            raise _RefusedError("steps: a task needs at least one step")
        assert isinstance(raw_steps, Mapping)
        steps = {str(name): self.step(body, f"steps.{name}.") for name, body in raw_steps.items()}
        names = list(steps)
        start = str(keys.get("start") or names[0])
        retract_keys = _load(RETRACT_SCHEMA, keys.get("retract") or {}, "retract.")
        retract = Retract(**RETRACT_SCHEMA.attrs(retract_keys))  # type: ignore[arg-type]
        task = Task(
            name=str(keys["task"]) if "task" in keys else "",
            steps=steps,
            start=start,
            approach=str(keys.get("approach", "-z")),
            approach_frame=str(keys.get("approach_frame", "fixed")),
            surface=keys.get("surface"),  # type: ignore[arg-type]
            force_ceiling=float(keys.get("force_ceiling", 25.0)),  # type: ignore[arg-type]
            torque_ceiling=float(keys.get("torque_ceiling", 2.0)),  # type: ignore[arg-type]
            time_limit=float(keys.get("time_limit", 0.0)),  # type: ignore[arg-type]
            on_failure=str(keys.get("on_failure", "")),
            retract=retract,
            description=str(keys.get("description", "")),
            body_region=str(keys.get("body_region", "")),
        )
        if not task.name:
            raise _RefusedError("task: give the task a name (task: <name>)")
        self.check_names(task)
        self.check_limits(task)
        return task

    def step(self, data: object, where: str) -> Step:
        keys = _load(STEP_SCHEMA, data, where)
        raw_laws = keys.get("laws") or {}
        assert isinstance(raw_laws, Mapping)
        laws = {}
        for axis, body in raw_laws.items():
            if axis not in AXIS_NAMES:
                hint = difflib.get_close_matches(str(axis), AXIS_NAMES, n=1)
                said = (f"did you mean {where}laws.{hint[0]}?" if hint
                        else f"the axes are {', '.join(AXIS_NAMES)}")
                raise _RefusedError(f"{where}laws.{axis} is not an axis: {said}")
            law_keys = _load(LAW_SCHEMA, body, f"{where}laws.{axis}.")
            laws[str(axis)] = Law(**LAW_SCHEMA.attrs(law_keys))  # type: ignore[arg-type]
        self.check_laws(laws, where)
        pattern_keys = _load(PATTERN_SCHEMA, keys.get("pattern") or {}, f"{where}pattern.")
        pattern = Pattern(**PATTERN_SCHEMA.attrs(pattern_keys))  # type: ignore[arg-type]
        wrong = [k for k in pattern_keys if k != "type" and k not in _PATTERN_KEYS[pattern.type]]
        if wrong:
            raise _RefusedError(f"{where}pattern.{wrong[0]}: not read by a {pattern.type} pattern (it reads "
                           f"{', '.join(_PATTERN_KEYS[pattern.type]) or 'nothing'})")
        raw_exits = keys.get("exits") or []
        if not isinstance(raw_exits, list) or not raw_exits:
            raise _RefusedError(f"{where}exits: a step needs a list of at least one exit (else it never "
                                "ends)")
        exits = tuple(self.exit(e, f"{where}exits[{i}].", pattern) for i, e in enumerate(raw_exits))
        path_axes = [a for a, law in laws.items() if law.law == "path"]
        if pattern.type != "none" and not path_axes:
            raise _RefusedError(f"{where}pattern: a {pattern.type} pattern moves the path law's reference; "
                                "give at least one axis law: path")
        if pattern.type == "path":
            pattern = self.path(pattern, laws, where)
        law_frame = str(keys.get("law_frame", "fixed"))
        if not _TF_NAME.fullmatch(law_frame):
            raise _RefusedError(f"{where}law_frame: {law_frame!r} is not a tf frame name (fixed, tool, or a "
                                "frame's name: letters, digits, _ . / -)")
        return Step(laws=laws, pattern=pattern, frame=str(keys.get("frame", "tool")), exits=exits,
                    law_frame=law_frame)

    def path(self, pattern: Pattern, laws: Mapping[str, Law], where: str) -> Pattern:
        """A path pattern checked: its poses make a path, one force per segment for a force-tracking axis."""
        try:
            path = PosePath(pattern.poses, pattern.speed, pattern.angular_speed, pattern.ramp)
        except TaskError as err:
            raise _RefusedError(f"{where}pattern.poses: {err}") from None
        if pattern.forces:
            if len(pattern.forces) != path.segments:
                raise _RefusedError(f"{where}pattern.forces: {len(pattern.forces)} for {path.segments} "
                                    "segments (one per segment)")
            if not any(law.law == "force_tracking" for law in laws.values()):
                raise _RefusedError(f"{where}pattern.forces: no axis has law: force_tracking to take them")
        poses = tuple(tuple(float(x) for x in row) for row in pattern.poses)
        return replace(pattern, poses=poses)

    def check_laws(self, laws: Mapping[str, Law], where: str) -> None:
        try:
            validate_laws_request(laws_request(laws))
        except RequestError as err:
            raise _RefusedError(f"{where}laws: {err}") from None

    def exit(self, data: object, where: str, pattern: Pattern) -> Exit:
        keys = _load(EXIT_SCHEMA, data, where)
        built = Exit(**EXIT_SCHEMA.attrs(keys))  # type: ignore[arg-type]
        outcomes = [k for k in ("next", "succeed", "fail") if keys.get(k)]
        if len(outcomes) != 1:
            raise _RefusedError(f"{where.rstrip('.')}: give exactly one of next, succeed, fail; got "
                           f"{', '.join(outcomes) or 'none'}")
        thresholds = [k for k in ("above", "below") if keys.get(k) is not None]
        if built.when in _THRESHOLD_EXITS and len(thresholds) != 1:
            raise _RefusedError(f"{where.rstrip('.')}: a {built.when} exit needs exactly one of above, below")
        if built.when not in _THRESHOLD_EXITS and (thresholds or "for" in keys):
            extra = (thresholds or ["for"])[0]
            raise _RefusedError(f"{where}{extra}: not read by a {built.when} exit")
        if built.when == "timeout" and "after" not in keys:
            raise _RefusedError(f"{where.rstrip('.')}: a timeout exit needs after: <seconds>")
        if built.when == "pattern_done" and pattern.type == "none":
            raise _RefusedError(f"{where.rstrip('.')}: pattern_done, but the step has no pattern")
        return built

    def check_names(self, task: Task) -> None:
        names = list(task.steps)
        if task.start not in task.steps:
            raise _RefusedError(f"start: no step {task.start!r}: {_closest(task.start, names)}")
        if task.on_failure and task.on_failure not in task.steps:
            raise _RefusedError(f"on_failure: no step {task.on_failure!r}: "
                                f"{_closest(task.on_failure, names)}")
        for name, step in task.steps.items():
            for i, e in enumerate(step.exits):
                if e.next and e.next not in task.steps:
                    raise _RefusedError(f"steps.{name}.exits[{i}].next: no step {e.next!r}: "
                                        f"{_closest(e.next, names)}")
        reached, todo = set(), [task.start] + ([task.on_failure] if task.on_failure else [])
        while todo:
            name = todo.pop()
            if name not in reached:
                reached.add(name)
                todo.extend(e.next for e in task.steps[name].exits if e.next)
        unreached = [n for n in names if n not in reached]
        if unreached:
            raise _RefusedError(f"steps.{unreached[0]}: no exit leads to it (from start {task.start!r})")

    def check_limits(self, task: Task) -> None:
        for name, step in task.steps.items():
            for axis, law in step.laws.items():
                ceiling = task.torque_ceiling if axis.startswith("r") else task.force_ceiling
                if abs(law.force_limit) > ceiling:
                    raise _RefusedError(f"steps.{name}.laws.{axis}.force_limit: {abs(law.force_limit):g} is "
                                        f"above the task's ceiling {ceiling:g}: it could never end the move")
            for i, e in enumerate(step.exits):
                if e.when != "force" or e.above is None:
                    continue
                ceiling = task.torque_ceiling if e.axis.startswith("r") else task.force_ceiling
                if abs(e.above) >= ceiling:
                    raise _RefusedError(f"steps.{name}.exits[{i}].above: {e.above:g} is not below the task's "
                                   f"ceiling {ceiling:g}: the ceiling fails the task first")


def laws_request(laws: Mapping[str, Law], frame: str = "") -> object:
    """A ConfigureLaws-shaped request (`contact_control.request.empty_laws_request`) of the laws along
    `frame` ("": contact_control's control_frame); axes left out are NONE. The node copies it into the genpy
    request field by field."""
    req = empty_laws_request()
    req.frame = frame
    for axis, law in laws.items():
        a = getattr(req, axis)
        a.law, a.exceeded_action = _LAW_CODES[law.law], _ACTION_CODES[law.exceeded_action]
        a.damping, a.stiffness, a.velocity = law.damping, law.stiffness, law.velocity
        a.force_limit, a.max_travel, a.target_force = law.force_limit, law.max_travel, law.target_force
    return req
