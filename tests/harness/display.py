"""A private X display (Xvfb, Mesa's software OpenGL) for tests of windows: MuJoCo's viewer, RViz."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager

HAVE_XVFB = bool(shutil.which("Xvfb") and shutil.which("xwininfo"))
NO_XVFB = "needs Xvfb and xwininfo (scripts/bootstrap installs xvfb, x11-utils)"

_GRAB = """
import sys
from python_qt_binding.QtWidgets import QApplication
app = QApplication(sys.argv[:1])
sys.exit(0 if app.primaryScreen().grabWindow(0).save(sys.argv[1]) else 1)
"""


@contextmanager
def private_display(size: str = "1024x768x24") -> Iterator[str]:
    """":N" of a new Xvfb; it picks a free number itself (-displayfd), so runs cannot collide."""
    read_end, write_end = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write_end), "-screen", "0", size, "-nolisten", "tcp"],
                            pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_end)
    try:
        with os.fdopen(read_end) as pipe:
            number = pipe.readline().strip()  # written once the server accepts connections
        assert number, "Xvfb did not start"
        yield f":{number}"
    finally:
        xvfb.terminate()
        xvfb.wait(timeout=10)


def windows(display: str) -> str:
    """`xwininfo -root -tree` of the display: every window's title."""
    return subprocess.run(["xwininfo", "-root", "-tree"], capture_output=True, text=True, timeout=10,
                          env={**os.environ, "DISPLAY": display}).stdout


def screenshot(display: str, path: str) -> None:
    """The whole screen as a PNG (Qt's grab of the root window, in its own process)."""
    env = {**os.environ, "DISPLAY": display}
    env.pop("QT_QPA_PLATFORM", None)
    run = subprocess.run([sys.executable, "-c", _GRAB, path], capture_output=True, text=True, timeout=30,
                         env=env)
    assert run.returncode == 0, run.stderr
