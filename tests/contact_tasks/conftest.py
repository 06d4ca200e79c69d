"""contact_tasks tests share the closed loop in hole_world.py (pytest runs with --import-mode=importlib, which
does not put test directories on sys.path)."""

import pathlib
import sys

_HERE = str(pathlib.Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)
