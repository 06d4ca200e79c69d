"""Task files are checked at load: a valid one becomes a Task, each bad one is refused naming the file, the
key and why (contact_tasks.task_file)."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
import yaml
from contact_tasks.task import TaskError
from contact_tasks.task_file import load_task, load_task_file, parse_task

SHIPPED = pathlib.Path(__file__).resolve().parents[2] / "src" / "contact_tasks" / "tasks"

GOOD = {
    "task": "probe",
    "steps": {
        "down": {
            "laws": {"z": {"law": "compliant_move", "velocity": -0.01, "damping": 2000.0,
                           "force_limit": 8.0}},
            "exits": [{"when": "touch", "next": "rub"},
                      {"when": "timeout", "after": 5.0, "fail": "no touch"}],
        },
        "rub": {
            "laws": {"z": {"law": "force_tracking", "target_force": 5.0, "damping": 2500.0},
                     "x": {"law": "path", "stiffness": 5.0, "damping": 1000.0}},
            "pattern": {"type": "line", "axis": "-x", "distance": 0.02, "speed": 0.01},
            "exits": [{"when": "pattern_done", "succeed": "rubbed"},
                      {"when": "force", "axis": "z", "above": 15.0, "for": 0.1, "fail": "pressed too hard"}],
        },
    },
}


def with_change(path: str, value: object) -> dict:
    """GOOD with the value at a dotted path set (None deletes the key)."""
    data = yaml.safe_load(yaml.safe_dump(GOOD))
    keys = path.split(".")
    node = data
    for key in keys[:-1]:
        node = node[int(key)] if isinstance(node, list) else node[key]
    last = keys[-1]
    if isinstance(node, list):
        node[int(last)] = value
    elif value is None:
        del node[last]
    else:
        node[last] = value
    return data


def test_a_valid_task_loads_with_its_steps_laws_pattern_and_exits_in_order():
    task = parse_task(GOOD, "probe.yaml")
    assert (task.name, task.start, list(task.steps)) == ("probe", "down", ["down", "rub"])
    rub = task.steps["rub"]
    assert rub.laws["z"].target_force == 5.0 and rub.pattern.type == "line" and rub.pattern.axis == "-x"
    assert [e.when for e in rub.exits] == ["pattern_done", "force"]
    assert rub.exits[1].for_ == 0.1 and rub.exits[1].above == 15.0
    assert (task.force_ceiling, task.approach, task.retract.distance) == (25.0, "-z", 0.02)


def test_a_task_may_name_the_body_region_jog_arm_guards_while_it_runs():
    assert parse_task(GOOD, "probe.yaml").body_region == ""  # the robot's own
    assert parse_task(with_change("body_region", "face"), "probe.yaml").body_region == "face"


def test_a_steps_laws_may_act_along_a_named_tf_frame_and_the_request_carries_it():
    from contact_tasks.run import Observation, TaskRun

    def sent(law_frame: str) -> str:
        task = parse_task(with_change("steps.down.law_frame", law_frame), "probe.yaml")
        return TaskRun(task, tool_frame="tool_tip").start(Observation(t=0.0, tool=np.eye(4))).laws.frame

    assert sent("hole_frame") == "hole_frame"  # contact_control refuses it, with the reason, if tf has none
    assert (sent("fixed"), sent("tool")) == ("", "tool_tip")
    # the tool's axes where the step began: the node puts that pose on tf under the run's start_frame
    task = parse_task(with_change("steps.down.law_frame", "tool_at_start"), "probe.yaml")
    tool = np.eye(4)
    tool[:3, 3] = (0.4, 0.1, 0.3)
    command = TaskRun(task, start_frame="here").start(Observation(t=0.0, tool=tool))
    assert command.laws.frame == "here" and np.array_equal(command.frame_pose, tool)
    assert TaskRun(parse_task(GOOD, "probe.yaml")).start(Observation(t=0.0, tool=tool)).frame_pose is None


def test_every_shipped_task_file_loads():
    files = sorted(SHIPPED.glob("*.yaml"))
    assert files
    for path in files:
        assert load_task_file(path).steps


DOWN_EXIT, RUB_EXIT = "steps.down.exits", "steps.rub.exits"
BAD = [
    ("tsak", "probe", "tsak is not a parameter: did you mean task?"),
    (f"{DOWN_EXIT}.0", {"when": "touch", "nxt": "rub"},
     "steps.down.exits[0].nxt is not a parameter: did you mean steps.down.exits[0].next?"),
    (f"{DOWN_EXIT}.0", {"when": "touch", "next": "rbu"},
     "steps.down.exits[0].next: no step 'rbu': did you mean 'rub'?"),
    (f"{DOWN_EXIT}.0", {"when": "touch", "fail": "x"}, "steps.rub: no exit leads to it"),
    (RUB_EXIT, [], "steps.rub.exits: a step needs a list of at least one exit"),
    (f"{DOWN_EXIT}.0", {"when": "touch", "next": "rub", "fail": "x"},
     "give exactly one of next, succeed, fail; got next, fail"),
    (f"{RUB_EXIT}.1", {"when": "force", "axis": "z", "fail": "x"},
     "a force exit needs exactly one of above, below"),
    (f"{DOWN_EXIT}.1", {"when": "timeout", "fail": "x"}, "a timeout exit needs after: <seconds>"),
    (f"{DOWN_EXIT}.1", {"when": "timeout", "after": 5, "above": 1.0, "fail": "x"},
     "steps.down.exits[1].above: not read by a timeout exit"),
    (f"{DOWN_EXIT}.1", {"when": "timeout", "after": -1, "fail": "x"},
     "steps.down.exits[1].after: must be > 0"),
    (f"{DOWN_EXIT}.1", {"when": "pattern_done", "fail": "x"}, "pattern_done, but the step has no pattern"),
    (f"{DOWN_EXIT}.1", {"when": "landed", "fail": "x"}, "steps.down.exits[1].when: must be one of"),
    ("steps.rub.pattern", {"type": "line", "pitch": 0.001},
     "steps.rub.pattern.pitch: not read by a line pattern"),
    ("steps.rub.pattern", {"type": "spiral", "max_radius": 0},
     "steps.rub.pattern.max_radius: must be in (0, 0.5], got 0"),
    ("steps.rub.laws", {"z": {"law": "force_tracking", "target_force": 5.0, "damping": 2500.0}},
     "a line pattern moves the path law's reference; give at least one axis law: path"),
    ("steps.down.laws", {"z": {"law": "spring", "damping": 100.0}},
     "steps.down.laws: axis z (spring): stiffness"),
    ("steps.down.laws", {"zz": {"law": "follower", "damping": 100.0}},
     "steps.down.laws.zz is not an axis: did you mean steps.down.laws.z?"),
    ("steps.down.laws", {"z": {"law": "folower", "damping": 100.0}}, "steps.down.laws.z.law: must be one of"),
    ("steps.down.laws.z.force_limit", 40.0,
     "steps.down.laws.z.force_limit: 40 is above the task's ceiling 25"),
    (f"{RUB_EXIT}.1", {"when": "force", "axis": "z", "above": 30.0, "fail": "x"},
     "steps.rub.exits[1].above: 30 is not below the task's ceiling"),
    ("start", "dwon", "start: no step 'dwon': did you mean 'down'?"),
    ("on_failure", "rubb", "on_failure: no step 'rubb': did you mean 'rub'?"),
    ("force_ceiling", 0, "force_ceiling: must be > 0"),
    ("retract", {"distance": 2.0}, "retract.distance: must be in (0, 0.5], got 2.0"),
    ("task", None, "task: give the task a name"),
    ("steps", {}, "steps: a task needs at least one step"),
    ("steps.down", [1, 2], "steps.down: expected a mapping of keys"),
    ("body_region", "hands", "body_region: must be one of ('', 'off', 'skull'"),
    ("steps.down.law_frame", "the hole", "steps.down.law_frame: 'the hole' is not a tf frame name"),
]


@pytest.mark.parametrize(("path", "value", "said"), BAD, ids=[b[2][:40] for b in BAD])
def test_a_bad_task_is_refused_naming_the_file_the_key_and_why(path, value, said):
    with pytest.raises(TaskError) as err:
        parse_task(with_change(path, value), "probe.yaml")
    assert str(err.value).startswith("probe.yaml: ")
    assert said in str(err.value)


def test_a_file_that_is_not_yaml_or_not_there_is_refused_naming_it(tmp_path):
    with pytest.raises(TaskError, match=r"^<goal>: not YAML"):
        load_task("steps: [", "<goal>")
    with pytest.raises(TaskError, match=r"missing.yaml: cannot read the task file"):
        load_task_file(tmp_path / "missing.yaml")
    with pytest.raises(TaskError, match=r"^x.yaml: the file: expected a mapping"):
        load_task("- 1", "x.yaml")


def test_overrides_merge_over_the_file_key_by_key_and_are_checked_like_it():
    text = yaml.safe_dump(GOOD)
    task = load_task(text, "probe.yaml", "{surface: 0.05, steps: {rub: {pattern: {distance: 0.03}}}}")
    assert task.surface == 0.05 and task.steps["rub"].pattern.distance == 0.03
    assert task.steps["rub"].pattern.axis == "-x"  # the rest of the pattern kept
    with pytest.raises(TaskError, match=r"^probe.yaml: steps.rub.pattern.distnce is not a parameter"):
        load_task(text, "probe.yaml", "{steps: {rub: {pattern: {distnce: 0.03}}}}")
    with pytest.raises(TaskError, match="the overrides must be a mapping"):
        load_task(text, "probe.yaml", "[1]")
