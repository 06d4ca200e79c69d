"""The parameter schema: one declaration gives the default, the checks with errors naming the key and what is
allowed, the unknown-key refusal with its did-you-mean, and the README table."""

from __future__ import annotations

import dataclasses
import math
import sys
import types
from typing import Any

import pytest
from compliant_common.schema import Param, Schema, SchemaError, param, schema_of
from compliant_common.schema_docs import render


@dataclasses.dataclass(frozen=True)
class Demo:
    rate: float = param(50.0, unit="Hz", gt=0.0, le=1000.0, doc="publish rate")
    topic: str = param("wrench", nonempty=True, doc="input topic")
    enabled: bool = param(True, doc="on | off")
    repeats: int = param(3, ge=1, doc="zeros sent")
    mode: str = param("unitless", choices=("unitless", "speed_units"), doc="command units")
    flip: int = param(1, type="sign", doc="sign flip")
    com: tuple[float, ...] = param((0.0, 0.0, 0.05), type="floats", length=3, unit="m", doc="centre of mass")
    names: tuple[str, ...] = param((), type="strings", doc="joints")
    limit: float | None = param(None, type="float", optional=True, gt=0.0, shown_default="= `rate`", doc="x")
    scale_linear: float = param(0.4, key="scale/linear", unit="m/s", gt=0.0, doc="nested key")
    overrides: dict[str, float] = param({}, type="mapping", doc="per joint")


SCHEMA = schema_of(Demo, extra=[Param("robot_description", "str", "", doc="read by the node")])


def test_the_declaration_gives_the_defaults_in_declaration_order() -> None:
    assert SCHEMA.names[:3] == ("rate", "topic", "enabled")
    assert SCHEMA.names[-2:] == ("overrides", "robot_description")
    defaults = Demo()
    for p in SCHEMA.values():
        if p.attr:
            assert getattr(defaults, p.attr) == p.default, p.name
    assert SCHEMA["scale/linear"].attr == "scale_linear" and SCHEMA["robot_description"].attr == ""
    assert Demo().overrides is not Demo().overrides, "a mutable default is copied per object"
    assert len(SCHEMA) == 12 and "rate" in SCHEMA and "nope" not in SCHEMA


def test_load_converts_what_is_given_and_leaves_the_rest_to_the_defaults() -> None:
    given = {"rate": 20, "com": [0, 0, 1], "names": ["a", "b"], "flip": -1.0, "scale/linear": 1}
    values = SCHEMA.load(given)
    assert values == {
        "rate": 20.0, "flip": -1, "com": (0.0, 0.0, 1.0), "names": ("a", "b"), "scale/linear": 1.0
    }
    assert isinstance(values["rate"], float) and isinstance(values["flip"], int)
    settings = Demo(**SCHEMA.attrs(values))
    assert settings.scale_linear == 1.0 and settings.topic == "wrench"
    assert SCHEMA.build(Demo, values) == settings  # the typed spelling of the line above
    assert SCHEMA.values_of(settings)["scale/linear"] == 1.0
    assert SCHEMA.load({"limit": None})["limit"] is None


BAD = [
    ({"rate": 0}, "rate: must be in (0, 1000], got 0"),
    ({"rate": 2000.0}, "rate: must be in (0, 1000], got 2000.0"),
    ({"rate": True}, "rate: expected a number, got True"),
    ({"rate": "fast"}, "rate: expected a number, got 'fast'"),
    ({"rate": math.nan}, "rate: must be finite, got nan"),
    ({"topic": ""}, "topic: must not be empty"),
    ({"topic": 3}, "topic: expected a string, got 3"),
    ({"enabled": "yes"}, "enabled: expected true or false, got 'yes'"),
    ({"repeats": 0}, "repeats: must be >= 1, got 0"),
    ({"repeats": 2.0}, "repeats: expected an integer, got 2.0"),
    ({"mode": "furlongs"}, "mode: must be one of ('unitless', 'speed_units'), got 'furlongs'"),
    ({"flip": 2}, "flip: must be 1 or -1, got 2"),
    ({"com": [0, 0]}, "com: expected a list of 3 numbers, got [0, 0]"),
    ({"com": [0, 0, math.inf]}, "com: must be finite, got inf"),
    ({"names": ["a", ""]}, "names: expected a list of non-empty strings, got ['a', '']"),
    ({"limit": -1.0}, "limit: must be > 0, got -1.0"),
    ({"overrides": [1]}, "overrides: expected a mapping, got [1]"),
    ({"robot_description": 5}, "robot_description: expected a string, got 5"),
]


@pytest.mark.parametrize(("params", "message"), BAD, ids=[m.split(":")[0] for _, m in BAD])
def test_a_bad_value_is_refused_naming_the_key_and_what_is_allowed(
    params: dict[str, Any], message: str
) -> None:
    with pytest.raises(SchemaError) as err:
        SCHEMA.load(params)
    assert str(err.value) == message
    assert err.value.key == next(iter(params))


def test_an_unknown_key_is_refused_with_the_closest_valid_one() -> None:
    with pytest.raises(SchemaError) as err:
        SCHEMA.load({"rate": 10.0, "rtae": 1.0}, prefix="~")
    assert err.value.key == "rtae"
    assert err.value.message == "~rtae is not a parameter: did you mean ~rate?"
    with pytest.raises(SchemaError, match="zzz is not a parameter: see the package README"):
        SCHEMA.load({"zzz": 1})
    SCHEMA.load({"extra_key": 1}, also_known=["extra_key"])
    with pytest.raises(SchemaError, match="did you mean extra_key"):
        SCHEMA.load({"extra_kee": 1}, also_known=["extra_key"])
    assert SCHEMA.unknown(["rate", "b", "a"]) == ["a", "b"]


def test_check_validates_values_already_in_settings_form() -> None:
    SCHEMA.check(SCHEMA.values_of(Demo()))
    with pytest.raises(SchemaError, match="rate"):
        SCHEMA.check({"rate": -1.0})


def test_a_bad_declaration_fails_at_import() -> None:
    with pytest.raises(TypeError, match=r"default -1\.0 is invalid: must be > 0"):
        Param("x", "float", -1.0, gt=0.0)
    with pytest.raises(TypeError, match="unknown type"):
        Param("x", "complex", 1.0)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="give type="):
        param((1.0, 2.0))
    with pytest.raises(ValueError, match="declared twice"):
        Schema([Param("x", "int", 1), Param("x", "int", 2)])


def test_the_table_has_one_row_per_key_with_default_unit_range_and_doc() -> None:
    rows = SCHEMA.table(prefix="~").splitlines()
    assert rows[0] == "| parameter | default | unit | range | meaning |"
    assert len(rows) == 2 + len(SCHEMA)
    assert rows[2] == "| `~rate` | 50.0 | Hz | in (0, 1000] | publish rate |"
    assert rows[3] == "| `~topic` | `wrench` | | not empty | input topic |"
    assert rows[4] == "| `~enabled` | true | | | on \\| off |"
    assert rows[5] == "| `~repeats` | 3 | | >= 1 | zeros sent |"
    assert rows[6] == "| `~mode` | `unitless` | | `unitless` / `speed_units` | command units |"
    assert rows[7] == "| `~flip` | 1 | | 1 / -1 | sign flip |"
    assert rows[8] == "| `~com` | [0.0, 0.0, 0.05] | m | | centre of mass |"
    assert rows[9] == "| `~names` | [] | | | joints |"
    assert rows[10] == "| `~limit` | = `rate` | | > 0 | x |"
    assert rows[11] == "| `~scale/linear` | 0.4 | m/s | > 0 | nested key |"
    assert rows[12] == "| `~overrides` | {} | | | per joint |"


def test_render_replaces_only_the_marked_tables(monkeypatch: pytest.MonkeyPatch) -> None:
    module = types.ModuleType("schema_demo")
    module.SCHEMA = SCHEMA  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "schema_demo", module)
    begin = "<!-- params:begin schema_demo:SCHEMA prefix=~ -->\n"
    text = f"# pkg\n\nprose\n\n{begin}old table\n<!-- params:end -->\n\nmore prose\n"
    out = render(text)
    assert out.startswith(f"# pkg\n\nprose\n\n{begin}<!-- generated")
    assert "old table" not in out and "| `~rate` | 50.0 |" in out
    assert out.endswith("<!-- params:end -->\n\nmore prose\n")
    assert render(out) == out
