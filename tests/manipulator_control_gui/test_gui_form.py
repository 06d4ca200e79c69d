"""The Qt-free form: form -> ConfigureForceControl / ConfigureLaws request, refusals before sending, presets,
answers."""

import dataclasses
import io
import math

import pytest
import yaml
from cartesian_impedance_msgs.srv import ConfigureForceControlRequest
from compliant_control_msgs.srv import ConfigureLawsRequest
from contact_control.request import validate_laws_request, validate_request
from manipulator_control_gui.form import (
    EXCEEDED_ACTIONS,
    AxisForm,
    FormError,
    build_laws_request,
    build_request,
    default_form,
    describe_response,
    form_from_dict,
    form_to_dict,
    law_form,
    preset_form,
    summarize_form,
    validate_form,
)
from manipulator_control_gui.form_config import (
    AXES,
    DEFAULT_CONFIG_PATH,
    LAW_FIELDS,
    LAWS,
    FormConfigError,
    load_config,
)

CONFIG = load_config()
LAW_TYPE = {"none": 0, "follower": 1, "spring": 2, "compliant_move": 3}
# Where each form field goes, written out independently of the code under test (SPEC section 3).
SLOTS = {
    False: {
        "damping": "damping.translational",
        "stiffness": "stiffness.translational",
        "velocity": "max_cart_vel.set.linear",
        "max_force": "max_ctrl_force.set.force",
        "max_deviation": "max_path_deviation.translation",
    },
    True: {
        "damping": "damping.rotational",
        "stiffness": "stiffness.rotational",
        "velocity": "max_cart_vel.set.angular",
        "max_force": "max_ctrl_force.set.torque",
        "max_deviation": "max_path_deviation.rotation",
    },
}
# Distinct values inside every range, so a value in the wrong slot is noticed.
VALUES = {"damping": 12.5, "stiffness": 7.0, "velocity": -0.015, "max_force": 3.5, "max_deviation": 0.12}


def slot(req, axis: str, field: str) -> float:
    node = req.cart_impedance_params
    for part in SLOTS[axis.startswith("r")][field].split("."):
        node = getattr(node, part)
    return getattr(node, axis[-1])


def wire(req) -> bytes:
    buffer = io.BytesIO()
    req.serialize(buffer)
    return buffer.getvalue()


def form_with(**rows: AxisForm) -> dict:
    form = default_form()
    form.update(rows)
    return form


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("axis", AXES)
def test_every_law_on_every_axis_maps_every_field(axis, law):
    # Every field filled in, also the ones the law does not use: those must be sent as 0.
    row = AxisForm(law, **VALUES)
    req = build_request(CONFIG, form_with(**{axis: row}))

    for other in AXES:
        assert getattr(req.direction_control_laws, other).type == (LAW_TYPE[law] if other == axis else 0)
        for field in VALUES:
            expected = VALUES[field] if other == axis and field in LAW_FIELDS[law] else 0.0
            assert slot(req, other, field) == expected, (other, field)
    assert req.cart_impedance_params.max_ctrl_force.exceeded_action.stop is True
    # The receiver's own decoding agrees (contact_control's validate_request on the same request).
    decoded = validate_request(req)[AXES.index(axis)]
    assert decoded.law == LAW_TYPE[law]
    if law != "none":
        assert decoded.damping == VALUES["damping"]
        assert decoded.force_limit == VALUES["max_force"]
        assert decoded.max_travel == VALUES["max_deviation"]
    if law == "spring":
        assert decoded.stiffness == VALUES["stiffness"]
    if law == "compliant_move":
        assert decoded.velocity == VALUES["velocity"]


def test_all_axes_at_once_keep_their_own_slots():
    rows = {
        axis: AxisForm(
            "compliant_move",
            damping=10 + i,
            velocity=0.01 * (i + 1),
            max_force=1 + i,
            max_deviation=0.01 * (i + 1),
        )
        for i, axis in enumerate(AXES)
    }
    req = build_request(CONFIG, rows)
    for i, axis in enumerate(AXES):
        assert getattr(req.direction_control_laws, axis).type == 3
        assert slot(req, axis, "damping") == 10 + i
        assert slot(req, axis, "velocity") == pytest.approx(0.01 * (i + 1))
        assert slot(req, axis, "max_force") == 1 + i
        assert slot(req, axis, "max_deviation") == pytest.approx(0.01 * (i + 1))
    assert [law.law for law in validate_request(req)] == [3] * 6


NAN = float("nan")
REFUSED = [
    # (axis, row, field, words the message must contain)
    ("z", AxisForm("follower", damping=0.0), "damping", ["Axis Z", "follower", "damping b", "above 0"]),
    ("x", AxisForm("follower", damping=-5.0), "damping", ["Axis X", "damping b", "outside"]),
    ("y", AxisForm("spring", damping=0.0, stiffness=100.0), "damping", ["Axis Y", "spring", "damping b"]),
    ("x", AxisForm("spring", damping=30.0, stiffness=0.0), "stiffness", ["Axis X", "stiffness k", "above 0"]),
    ("rz", AxisForm("spring", damping=30.0, stiffness=-1.0), "stiffness", ["Axis RZ", "stiffness k"]),
    (
        "z",
        AxisForm("compliant_move", damping=30.0, velocity=0.0, max_force=0.5),
        "velocity",
        ["Axis Z", "compliant move", "desired velocity", "not be 0"],
    ),
    (
        "x",
        AxisForm("compliant_move", damping=30.0, velocity=0.02),
        "max_deviation",
        ["Axis X", "max force/torque", "max path deviation", "never end"],
    ),
    ("z", AxisForm("follower", damping=NAN), "damping", ["Axis Z", "damping b", "not a number"]),
    (
        "ry",
        AxisForm("compliant_move", damping=30.0, velocity=NAN, max_force=1.0),
        "velocity",
        ["Axis RY", "desired velocity", "not a number"],
    ),
    (
        "y",
        AxisForm("compliant_move", damping=30.0, velocity=0.02, max_force=math.inf),
        "max_force",
        ["Axis Y", "max force/torque", "not a number"],
    ),
    (
        "x",
        AxisForm("compliant_move", damping=30.0, velocity=0.5, max_force=1.0),
        "velocity",
        ["Axis X", "0.5 m/s", "outside -0.3 to 0.3 m/s"],
    ),
    ("rx", AxisForm("follower", damping=30.0, max_force=-1.0), "max_force", ["Axis RX", "N·m", "outside"]),
    (
        "z",
        AxisForm("spring", damping=30.0, stiffness=100.0, max_deviation=NAN),
        "max_deviation",
        ["Axis Z", "max path deviation", "not a number"],
    ),
    ("y", AxisForm("jump"), "law", ["Axis Y", "unknown law"]),
]


@pytest.mark.parametrize(("axis", "row", "field", "words"), REFUSED)
def test_invalid_input_is_caught_before_sending(axis, row, field, words):
    req = ConfigureForceControlRequest()
    before = wire(req)
    with pytest.raises(FormError) as caught:
        build_request(CONFIG, form_with(**{axis: row}), req)
    err = caught.value
    assert (err.axis, err.field) == (axis, field)
    for word in words:
        assert word in err.message
    # Nothing was written into the request object either.
    assert wire(req) == before


def test_unused_fields_may_hold_anything_and_are_not_sent():
    # A NaN left in a field the law hides must neither block nor travel.
    row = AxisForm("follower", damping=30.0, stiffness=NAN, velocity=NAN)
    req = build_request(CONFIG, form_with(z=row))
    assert slot(req, "z", "stiffness") == 0.0 and slot(req, "z", "velocity") == 0.0


def test_compliant_move_needs_only_one_end_condition():
    force_only = AxisForm("compliant_move", damping=0.0, velocity=-0.02, max_force=0.5)
    travel_only = AxisForm("compliant_move", damping=30.0, velocity=0.02, max_deviation=0.1)
    for row in (force_only, travel_only):
        validate_form(CONFIG, form_with(z=row))  # no exception
        build_request(CONFIG, form_with(z=row))


def test_contact_control_check_runs_after_the_form(tmp_path):
    # A config whose range lets a negative force limit through the form: contact_control's own check
    # must still refuse it, with its error code, and the message says so in words.
    data = yaml.safe_load(DEFAULT_CONFIG_PATH.read_text())
    data["fields"]["max_force"]["linear"]["min"] = -5.0
    path = tmp_path / "wide.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True))
    wide = load_config(path)
    row = AxisForm("follower", damping=30.0, max_force=-1.0)
    validate_form(wide, form_with(x=row))  # the form alone accepts it
    with pytest.raises(FormError) as caught:
        build_request(wide, form_with(x=row))
    assert caught.value.code == -2  # SET_CONTROL_FORCE_FAILED
    assert "contact_control would refuse this" in caught.value.message
    assert "axis x" in caught.value.message


def fields_of(req) -> dict:
    """Every non-zero mapped value of a request, keyed 'axis.field', plus the laws."""
    out = {}
    for axis in AXES:
        law = getattr(req.direction_control_laws, axis).type
        if law:
            out[f"{axis}.law"] = law
        for field in VALUES:
            value = slot(req, axis, field)
            if value:
                out[f"{axis}.{field}"] = value
    return out


THESIS = {
    # thesis section 6.4; the desired velocities are the GUI's documented choice (README, gui.yaml)
    "follower_z": {"z.law": 1, "z.damping": 30.0},
    "compliant_move_z": {"z.law": 3, "z.damping": 30.0, "z.velocity": -0.02, "z.max_force": 0.5},
    "spring_x": {"x.law": 2, "x.damping": 30.0, "x.stiffness": 100.0},
    "hybrid": {
        "x.law": 3,
        "x.damping": 30.0,
        "x.velocity": 0.02,
        "x.max_force": 0.5,
        "x.max_deviation": 0.30,
        "z.law": 2,
        "z.damping": 30.0,
        "z.stiffness": 100.0,
    },
}


@pytest.mark.parametrize("name", THESIS)
def test_presets_produce_the_thesis_requests(name):
    req = build_request(CONFIG, preset_form(CONFIG, name))
    assert fields_of(req) == THESIS[name]
    validate_request(req)  # contact_control accepts it


def test_presets_are_all_tested():
    assert set(CONFIG.presets) == set(THESIS)


def test_picking_a_law_starts_from_its_configured_values():
    assert law_form(CONFIG, "z", "follower") == AxisForm("follower", damping=30.0)
    assert law_form(CONFIG, "x", "spring") == AxisForm("spring", damping=30.0, stiffness=100.0)
    move = law_form(CONFIG, "rx", "compliant_move")
    assert move.velocity == 0.05 and move.max_force == 0.5 and move.max_deviation == 0.5
    for axis in AXES:
        for law in LAWS:
            build_request(CONFIG, form_with(**{axis: law_form(CONFIG, axis, law)}))  # each start is sendable


def test_ranges_are_at_least_the_original_sliders_and_units_follow_the_axis():
    wanted = {"damping": 300.0, "stiffness": 100.0, "velocity": 0.3, "max_force": 25.0, "max_deviation": 0.3}
    for field, top in wanted.items():
        spec = CONFIG.spec(field, "x")
        assert spec.minimum <= 0.0 and spec.maximum >= top, field
    assert CONFIG.spec("velocity", "x").minimum <= -0.3  # both directions
    assert CONFIG.spec("velocity", "x").unit == "m/s" and CONFIG.spec("velocity", "rx").unit == "rad/s"
    assert CONFIG.spec("max_force", "y").unit == "N" and CONFIG.spec("max_force", "rz").unit == "N·m"
    assert CONFIG.spec("max_deviation", "z").unit == "m" and CONFIG.spec("max_deviation", "ry").unit == "rad"


@pytest.mark.parametrize(
    ("edit", "key"),
    [
        (lambda d: d["fields"]["damping"]["linear"].update(min=400.0), "fields.damping.linear"),
        (lambda d: d["fields"]["stiffness"]["angular"].pop("unit"), "fields.stiffness.angular.unit"),
        (lambda d: d["laws"]["spring"]["linear"].pop("stiffness"), "laws.spring.linear"),
        (lambda d: d["laws"]["follower"]["linear"].update(damping=1000.0), "laws.follower.linear.damping"),
        (lambda d: d["presets"]["hybrid"]["axes"].update(w={"law": "spring"}), "presets.hybrid.axes.w"),
        (lambda d: d["presets"]["spring_x"]["axes"]["x"].update(law="push"), "presets.spring_x.axes.x.law"),
        (
            lambda d: d["presets"]["follower_z"]["axes"]["z"].update(velocity=0.1),
            "presets.follower_z.axes.z.velocity",
        ),
    ],
)
def test_bad_config_is_refused_naming_the_key(tmp_path, edit, key):
    data = yaml.safe_load(DEFAULT_CONFIG_PATH.read_text())
    edit(data)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True))
    with pytest.raises(FormConfigError) as caught:
        load_config(path)
    assert caught.value.key == key


def test_responses_in_plain_words():
    assert describe_response(True, 1) == "Applied: contact control accepted the laws."
    words = {
        99999: ["Reset", "FAILURE"],
        -1: ["unknown law", "SET_DOF_FAILED"],
        -2: ["max force/torque", "SET_CONTROL_FORCE_FAILED"],
        -3: ["stiffness", "SET_FORCE_STIFFNESS_FAILED"],
        -4: ["damping, desired velocity or max path deviation", "SET_CARTESIAN_CONTROL_FAILED"],
    }
    for code, parts in words.items():
        text = describe_response(False, code)
        assert text.startswith("Refused:")
        for part in parts:
            assert part in text
    assert "unknown code" in describe_response(False, 42)
    assert "with code SUCCESS" in describe_response(False, 1)
    # The service reply cannot carry a code (CartesianForceCtrlErrorCodes has no fields): say what it can be.
    assert describe_response(False, -4, "axis x (compliant_move): desired velocity 0.3 m/s exceeds 0.25") == (
        "Refused: axis x (compliant_move): desired velocity 0.3 m/s exceeds 0.25 "
        "(error SET_CARTESIAN_CONTROL_FAILED, -4)."
    )
    text = describe_response(False)
    assert text.startswith("Refused: contact control did not accept the laws.") and "press Reset" in text


def test_error_table_covers_every_message_code():
    from cartesian_impedance_msgs.msg import CartesianForceCtrlErrorCodes as Codes

    for name in (
        "FAILURE",
        "SET_DOF_FAILED",
        "SET_CONTROL_FORCE_FAILED",
        "SET_FORCE_STIFFNESS_FAILED",
        "SET_CARTESIAN_CONTROL_FAILED",
    ):
        assert name in describe_response(False, getattr(Codes, name))


def test_summary_and_saved_form_round_trip():
    form = preset_form(CONFIG, "hybrid")
    assert summarize_form(CONFIG, form) == "X compliant move, Z spring"
    assert summarize_form(CONFIG, default_form()).startswith("all axes none")
    assert form_from_dict(form_to_dict(form)) == form
    # An old or damaged save loads what it can.
    damaged = form_to_dict(form)
    damaged["x"]["law"] = "teleport"
    damaged["z"]["damping"] = "lots"
    restored = form_from_dict(damaged)
    assert restored["x"] == AxisForm() and restored["z"] == dataclasses.replace(form["z"], damping=0.0)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("axis", AXES)
def test_every_law_on_every_axis_maps_to_the_configure_laws_request(axis, law):
    row = AxisForm(law, **VALUES)
    req = build_laws_request(CONFIG, form_with(**{axis: row}), action="move_away")
    assert isinstance(req, ConfigureLawsRequest)
    names = {"damping": "damping", "stiffness": "stiffness", "velocity": "velocity",
             "max_force": "force_limit", "max_deviation": "max_travel"}
    for other in AXES:
        target = getattr(req, other)
        assert target.law == (LAW_TYPE[law] if other == axis else 0)
        for field, slot_name in names.items():
            expected = VALUES[field] if other == axis and field in LAW_FIELDS[law] else 0.0
            assert getattr(target, slot_name) == expected, (other, field)
        # The action goes to the axes with a max force (as contact_control maps the original's one flag).
        assert target.exceeded_action == (1 if other == axis and law != "none" else 0)
    decoded = validate_laws_request(req)[AXES.index(axis)]
    assert decoded.law == LAW_TYPE[law]


@pytest.mark.parametrize("action", list(EXCEEDED_ACTIONS))
def test_the_chosen_exceeded_action_is_the_one_flag_sent(action):
    form = form_with(z=AxisForm("compliant_move", damping=30.0, velocity=-0.02, max_force=0.5))
    flags = build_request(CONFIG, form, action=action).cart_impedance_params.max_ctrl_force.exceeded_action
    sent = {name: getattr(flags, name) for name in EXCEEDED_ACTIONS}
    assert sent == {name: name == action for name in EXCEEDED_ACTIONS}
    assert validate_request(build_request(CONFIG, form, action=action))[2].exceeded_action == (
        EXCEEDED_ACTIONS[action][0]
    )


def test_an_exceeded_action_contact_control_would_refuse_is_caught_before_sending():
    # Gravity compensation makes the axis a follower after the limit: a compliant move needs b > 0 for that.
    form = form_with(z=AxisForm("compliant_move", damping=0.0, velocity=-0.02, max_force=0.5))
    for build in (build_request, build_laws_request):
        with pytest.raises(FormError) as err:
            build(CONFIG, form, action="gravity_compensation")
        assert err.value.code == -4 and "damping" in err.value.message
    with pytest.raises(FormError, match="Unknown action"):
        build_laws_request(CONFIG, form, action="explode")


def test_panel_parameters_are_declared_once_and_unknown_keys_refused():
    from manipulator_control_gui.params import load_settings
    from manipulator_control_gui.ros_client import RosNames

    assert RosNames.from_settings(load_settings({})) == RosNames()
    names = RosNames.from_settings(
        load_settings({"contact_control_node": "/robot/cc/", "configure_service": "/robot/configure"})
    )
    assert (names.tare_service, names.status_topic) == ("/robot/cc/tare", "/robot/cc/status")
    assert names.laws_service == "/robot/configure_laws"
    assert RosNames.from_settings(load_settings({"stop_service": "/halt"})).stop_service == "/halt"
    with pytest.raises(ValueError, match=r"^~retry_perod is not a parameter: did you mean ~retry_period\?$"):
        load_settings({"retry_perod": 2.0})
    with pytest.raises(ValueError, match=r"^~retry_period: must be > 0, got 0$"):
        load_settings({"retry_period": 0})
