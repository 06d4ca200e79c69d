"""Qt set-up for the GUI tests: offscreen platform, one QApplication, an event pump waiting on conditions."""

import os

# Before any Qt import: no display on CI machines.
os.environ["QT_QPA_PLATFORM"] = "offscreen"

import time
from collections.abc import Callable

import pytest


@pytest.fixture(scope="session")
def qapp():
    """The process's QApplication."""
    from python_qt_binding.QtWidgets import QApplication

    app = QApplication.instance() or QApplication(["pytest"])
    yield app


@pytest.fixture
def pump(qapp) -> Callable[..., None]:
    """`pump(predicate, timeout, message)`: runs the Qt event loop until predicate() is true.

    Raises AssertionError on timeout. Events keep flowing meanwhile, as in a running application.
    """
    from python_qt_binding.QtCore import QEventLoop

    def run(predicate: Callable[[], bool], timeout: float = 10.0, message: str = "condition") -> None:
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                raise AssertionError(f"timed out after {timeout} s waiting for {message}")
            qapp.processEvents(QEventLoop.AllEvents, 20)
            time.sleep(0.005)  # yield to the ROS threads between event batches

    return run
