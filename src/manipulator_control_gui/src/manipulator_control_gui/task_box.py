"""The panel's Task box: the task task_server runs (any client's), its step and numbers, and Cancel (see the
package README). The texts are pure functions of the action's messages (duck-typed)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from python_qt_binding.QtWidgets import QGroupBox, QHBoxLayout, QLabel, QPushButton

__all__ = ["TaskBox", "task_name", "task_outcome", "task_progress"]


def task_name(goal: Any) -> str:
    """The goal's task: its name, or 'a task file' when the YAML came inline."""
    return str(goal.task) if goal.task else "a task file"


def task_progress(name: str, feedback: Any) -> str:
    """One line of a running task: step, time, |F|, depth past the touch and the pattern's radius."""
    f = feedback.wrench.force
    force = math.sqrt(f.x * f.x + f.y * f.y + f.z * f.z)
    depth = "" if math.isnan(feedback.depth) else f", depth {feedback.depth * 1e3:.1f} mm"
    radius = f", search radius {feedback.search_radius * 1e3:.1f} mm" if feedback.search_radius > 0.0 else ""
    return f"{name}: step {feedback.step}, {feedback.elapsed:.1f} s, |F| {force:.1f} N{depth}{radius}"


def task_outcome(name: str, result: Any) -> str:
    """One line of an ended task: its outcome and reason, time and peaks."""
    seconds = sum(result.step_times)
    return (f"{name}: {result.outcome}: {result.message} ({seconds:.1f} s, peak |F| "
            f"{result.peak_force:.1f} N, |T| {result.peak_torque:.2f} Nm)")


class TaskBox(QGroupBox):
    """A line for the task (running or last ended) and Cancel.

    Args:
        cancel: cancels task_server's goals (the ROS client's `cancel_task`).
    """

    def __init__(self, cancel: Callable[[], None], parent: QGroupBox | None = None) -> None:
        super().__init__("Task (contact_tasks' task_server)", parent)
        self.setObjectName("task_box")
        self._name = "task"
        row = QHBoxLayout(self)
        self.task_label = QLabel("no task yet", self)
        self.task_label.setObjectName("task_label")
        self.task_label.setWordWrap(True)
        row.addWidget(self.task_label, 1)
        self.cancel_button = QPushButton("Cancel task", self)
        self.cancel_button.setObjectName("cancel_task_button")
        self.cancel_button.setToolTip("cancel the running task: contact_control stops its move, the arm "
                                      "holds")
        self.cancel_button.setEnabled(False)
        self.cancel_button.clicked.connect(cancel)
        row.addWidget(self.cancel_button)

    def show_goal(self, goal: Any) -> None:
        self._name = task_name(goal)
        self.task_label.setText(f"{self._name}: starting")
        self.cancel_button.setEnabled(True)

    def show_feedback(self, feedback: Any) -> None:
        self.task_label.setText(task_progress(self._name, feedback))
        self.cancel_button.setEnabled(True)

    def show_result(self, result: Any) -> None:
        self.task_label.setText(task_outcome(self._name, result))
        self.cancel_button.setEnabled(False)
