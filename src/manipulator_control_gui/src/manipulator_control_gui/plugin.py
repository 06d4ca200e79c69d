"""rqt plugin wrapper of the panel (see plugin.xml). Imports without rqt, so it is testable anywhere."""

from __future__ import annotations

import json

from manipulator_control_gui.form import EXCEEDED_ACTIONS, form_from_dict, form_to_dict

try:
    from qt_gui.plugin import Plugin
except ImportError:  # no rqt on this machine: a stand-in with the same constructor, enough to build the panel
    from python_qt_binding.QtCore import QObject

    class Plugin(QObject):  # type: ignore[no-redef]
        """Minimal stand-in for qt_gui.plugin.Plugin."""

        def __init__(self, context) -> None:
            super().__init__()
            self._context = context


__all__ = ["ManipulatorControlPlugin"]


class ManipulatorControlPlugin(Plugin):
    """rqt's 'Robot Tools > Manipulator Control'. rqt_gui_py has already initialised rospy."""

    def __init__(self, context) -> None:
        super().__init__(context)
        self.setObjectName("ManipulatorControlPlugin")
        from manipulator_control_gui.ros_app import create_widget

        self._widget = create_widget()
        if context.serial_number() > 1:
            self._widget.setWindowTitle(f"{self._widget.windowTitle()} ({context.serial_number()})")
        context.add_widget(self._widget)

    @property
    def widget(self):
        """The panel."""
        return self._widget

    def shutdown_plugin(self) -> None:
        self._widget.shutdown()

    def save_settings(self, plugin_settings, instance_settings) -> None:
        instance_settings.set_value("form", json.dumps(form_to_dict(self._widget.form())))
        instance_settings.set_value("exceeded_action", self._widget.exceeded_action)

    def restore_settings(self, plugin_settings, instance_settings) -> None:
        action = instance_settings.value("exceeded_action")
        if action in EXCEEDED_ACTIONS:
            self._widget.set_exceeded_action(action)
        saved = instance_settings.value("form")
        if not saved:
            return
        try:
            data = json.loads(saved)
        except (TypeError, ValueError):
            return  # an unreadable old save: keep the empty form
        if isinstance(data, dict):
            self._widget.set_form(form_from_dict(data))
