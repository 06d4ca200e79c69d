"""One error base for the stack (compliant_common.errors.StackError), and one name per error: catching
StackError catches every refusal, and a traceback's class name says which package refused."""

from __future__ import annotations

import pathlib
import re
from collections import defaultdict

from compliant_common.errors import StackError

SRC = pathlib.Path(__file__).resolve().parents[2] / "src"
CLASS = re.compile(r"^class (\w+(?:Error|Exception))\(([^)]*)\):", re.M)


def _error_classes() -> dict[str, list[tuple[str, str]]]:
    found: dict[str, list[tuple[str, str]]] = defaultdict(list)
    for path in SRC.glob("*/src/**/*.py"):
        for name, bases in CLASS.findall(path.read_text()):
            found[name].append((str(path.relative_to(SRC)), bases))
    return found


def test_every_error_of_the_stack_is_a_stack_error_with_a_name_of_its_own():
    found = _error_classes()
    assert len(found) > 20
    duplicated = {name: [p for p, _ in where] for name, where in found.items() if len(where) > 1}
    assert duplicated == {}

    def stack_error(name: str) -> bool:  # StackError itself, or a class of ours derived from one
        return name == "StackError" or (
            name in found and any(stack_error(base.strip()) for base in found[name][0][1].split(",")))

    outside = [f"{where[0][0]}: {name}({where[0][1]})" for name, where in found.items()
               if not stack_error(name)]
    assert outside == []


def test_a_stack_error_is_still_a_value_error():
    from jog_arm.settings import SettingsError
    from mujoco_driver.params import DriverParamError

    assert issubclass(SettingsError, StackError) and issubclass(DriverParamError, ValueError)
