"""The panel's private parameters, each declared once (no ROS): `PARAMETERS` validates them at start-up and
generates the README's table."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from compliant_common.schema import SchemaError, param, schema_of

__all__ = ["PARAMETERS", "GuiSettings", "load_settings"]


def _derived(shown: str, doc: str) -> Any:
    return param("", shown_default=shown, doc=f"{doc} (empty: the default)")


@dataclass(frozen=True)
class GuiSettings:
    """The panel's parameters (name, type, default, unit, range, doc declared here). Empty names are derived
    from `contact_control_node` and `configure_service` (`ros_client.RosNames.from_settings`)."""

    config: str = param(
        "", shown_default="the package's `config/gui.yaml`",
        doc="form description: field units, ranges, law start values, presets",
    )
    contact_control_node: str = param(
        "contact_control_node", nonempty=True,
        doc="name of the contact control node; its private services and status topic are looked up under it",
    )
    configure_service: str = param(
        "configure_cartesian_impedance", nonempty=True, doc="the non-blocking ConfigureForceControl service"
    )
    configure_laws_service: str = _derived(
        "`configure_laws` beside `~configure_service`",
        "the ConfigureLaws service, used when registered",
    )
    stop_service: str = _derived("`<contact_control_node>/stop`", "Trigger service of Stop")
    tare_service: str = _derived("`<contact_control_node>/tare`", "Trigger service of Tare")
    reset_service: str = _derived("`<contact_control_node>/reset`", "Trigger service of Reset")
    guide_service: str = _derived("`<contact_control_node>/guide`", "Guide service of the Guide toggle")
    status_topic: str = _derived("`<contact_control_node>/status`", "status topic of the readout")
    recover_service: str = param(
        "jog_arm_server/recover", nonempty=True,
        doc="jog_arm's Trigger service of Recover: after the robot stopped by itself, the driver's recovery "
        "and commands taken again (jog_arm README, *Robot stops*)",
    )
    teach_node: str = param(
        "teach", nonempty=True,
        doc="teach's program_server: the Teach box calls its `~record`, `~stop` and `~replay`",
    )
    task_server: str = param(
        "task_server", nonempty=True,
        doc="contact_tasks' task_server: the Task box shows the running task's step from its `~execute` "
        "action's feedback and result, and its Cancel cancels it",
    )
    retry_period: float = param(1.0, unit="s", gt=0.0, doc="how often the panel looks for the services")


PARAMETERS = schema_of(GuiSettings)


def load_settings(params: Mapping[str, Any]) -> GuiSettings:
    """Settings from the panel node's private parameters (`rospy.get_param("~")`).

    Raises:
        ValueError: An unknown key (naming the closest valid one) or a bad value, naming the key.
    """
    try:
        return PARAMETERS.build(GuiSettings, PARAMETERS.load(params, prefix="~"))
    except SchemaError as err:
        raise ValueError(err.named("~")) from None
