"""task_server's private parameters, each declared once (no ROS): `PARAMETERS` validates them at start-up and
generates the README's table."""

from __future__ import annotations

from dataclasses import dataclass

from compliant_common.schema import SchemaError, param, schema_of
from compliant_common.typedefs import ParamMap

from contact_tasks.task import TaskError

__all__ = ["PARAMETERS", "TaskServerSettings", "load_settings"]


@dataclass(frozen=True)
class TaskServerSettings:
    """The node's parameters (name, type, default, unit, range, doc declared here)."""

    tasks_dir: str = param("", shown_default="this package's `tasks/`",
                           doc="folder of the task files a goal names (`<task>.yaml`)")
    contact_control_node: str = param(
        "contact_control_node", nonempty=True,
        doc="where `~status`, `~events`, `~path_reference`, `~stop` and the frames' defaults are",
    )
    rate: float = param(100.0, unit="Hz", gt=0.0, le=200.0,
                        doc="steps checked and the path reference streamed this often (off contact_control's "
                        "cycle)")
    path_horizon: float = param(
        0.4, unit="s", ge=0.0, le=2.0,
        doc="each path reference carries where the pattern goes this far ahead, which contact_control "
        "follows when the stream is late (a stalled node) instead of stopping the tool. 0: none",
    )
    path_horizon_step: float = param(0.02, unit="s", gt=0.0, doc="the time between the horizon's poses")
    feedback_rate: float = param(10.0, unit="Hz", gt=0.0, le=100.0, doc="action feedback rate")
    jog_arm: str = param(
        "jog_arm_server", nonempty=True,
        doc="jog_arm's namespace: a task's `body_region` is set there (dynamic_reconfigure) while it runs",
    )
    status_timeout: float = param(2.0, unit="s", gt=0.0, doc="a task is refused when contact_control's "
                                  "`~status` has not come for this long")


PARAMETERS = schema_of(TaskServerSettings)


def load_settings(params: ParamMap) -> TaskServerSettings:
    """Settings from the node's private parameters.

    Raises:
        TaskError: naming the parameter and why.
    """
    try:
        return PARAMETERS.build(TaskServerSettings, PARAMETERS.load(params, prefix="~"))
    except SchemaError as err:
        raise TaskError(err.named("~")) from None
