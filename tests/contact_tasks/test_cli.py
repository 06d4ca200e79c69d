"""`task check FILE...`: validates without a ROS master, says OK or REFUSED with the reason, exit 1 if any
is refused."""

from __future__ import annotations

import pathlib

from contact_tasks.cli import main

SHIPPED = pathlib.Path(__file__).resolve().parents[2] / "src/contact_tasks/tasks/peg_in_hole.yaml"


def test_check_says_ok_or_refused_with_the_reason(tmp_path, capsys):
    assert main(["check", str(SHIPPED)]) == 0
    assert "OK " in capsys.readouterr().out
    bad = tmp_path / "bad.yaml"
    bad.write_text(SHIPPED.read_text().replace("force_ceiling: 25.0", "force_cieling: 25.0"))
    assert main(["check", str(SHIPPED), str(bad)]) == 1
    out = capsys.readouterr().out
    assert f"REFUSED {bad}: force_cieling is not a parameter: did you mean force_ceiling?" in out
