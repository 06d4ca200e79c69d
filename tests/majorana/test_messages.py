"""The message package keeps the original bundle's wire format, field for field."""

import shutil
import subprocess

import pytest
from cartesian_impedance_msgs import msg, srv

MD5 = {
    srv.ConfigureForceControl: "8354389c95567f947c082f76e42fcd23",
    srv.ConfigureCartesianImpedance: "31f5fc4d2c180546cc19c45ae4dc3939",
    msg.SetCartesianImpedance: "b24937cc6fdd3861e00c0a10eecbfb67",
    msg.ControlLaw: "911eebda8fb165d3573c47fd929c52a4",
    msg.DirectionControlLaws: "1d024e28bf3d8084ed587a0eb0ce6bfd",
    msg.CartesianImpedanceErrorCodes: "ebce641c819a67590ce717bdb7c4731b",
}

V3 = "geometry_msgs/Vector3"
FIELDS = {
    msg.CartesianStiffness: [("translational", V3), ("rotational", V3)],
    msg.CartesianDamping: [("translational", V3), ("rotational", V3)],
    msg.MaxCartesianVelocity: [("set", "geometry_msgs/Twist")],
    msg.MaxCtrlForceExceeded: [("stop", "bool"), ("gravity_compensation", "bool"), ("move_away", "bool")],
    msg.MaxControlForce: [
        ("set", "geometry_msgs/Wrench"),
        ("exceeded_action", "cartesian_impedance_msgs/MaxCtrlForceExceeded"),
    ],
    msg.MaxPathDeviation: [("translation", V3), ("rotation", V3)],
    msg.NullSpace: [("link_names", "string[]"), ("stiffness", "float64[]"), ("damping", "float64[]")],
    msg.SetCartesianImpedance: [
        ("tool", "string"),
        ("stiffness", "cartesian_impedance_msgs/CartesianStiffness"),
        ("damping", "cartesian_impedance_msgs/CartesianDamping"),
        ("max_cart_vel", "cartesian_impedance_msgs/MaxCartesianVelocity"),
        ("max_ctrl_force", "cartesian_impedance_msgs/MaxControlForce"),
        ("max_path_deviation", "cartesian_impedance_msgs/MaxPathDeviation"),
        ("null_space_params", "cartesian_impedance_msgs/NullSpace"),
    ],
    msg.SetCartesianForceCtrl: [("DOF", "string"), ("force", "float64"), ("stiffness", "float64")],
    msg.CartesianForceCtrlErrorCodes: [],
    msg.ControlLaw: [("type", "uint8")],
    msg.DirectionControlLaws: [
        (axis, "cartesian_impedance_msgs/ControlLaw") for axis in ("x", "y", "z", "rx", "ry", "rz")
    ],
    msg.CartesianImpedanceErrorCodes: [],
    srv.ConfigureForceControlRequest: [
        ("cart_impedance_params", "cartesian_impedance_msgs/SetCartesianImpedance"),
        ("cart_force_control", "cartesian_impedance_msgs/SetCartesianForceCtrl"),
        ("direction_control_laws", "cartesian_impedance_msgs/DirectionControlLaws"),
    ],
    srv.ConfigureForceControlResponse: [
        ("success", "bool"),
        ("error", "cartesian_impedance_msgs/CartesianForceCtrlErrorCodes"),
    ],
    srv.ConfigureCartesianImpedanceRequest: [
        ("cart_impedance_params", "cartesian_impedance_msgs/SetCartesianImpedance"),
    ],
    srv.ConfigureCartesianImpedanceResponse: [
        ("success", "bool"),
        ("error", "cartesian_impedance_msgs/CartesianImpedanceErrorCodes"),
    ],
}

CONSTANTS = {
    msg.ControlLaw: {"TYPE_UNKNOWN": 0, "TYPE_FOLLOWER": 1, "TYPE_SPRING": 2, "TYPE_COMPLIANT_MOVE": 3},
    msg.CartesianForceCtrlErrorCodes: {
        "SUCCESS": 1, "FAILURE": 99999, "SET_DOF_FAILED": -1, "SET_CONTROL_FORCE_FAILED": -2,
        "SET_FORCE_STIFFNESS_FAILED": -3, "SET_CARTESIAN_CONTROL_FAILED": -4,
    },
    msg.CartesianImpedanceErrorCodes: {
        "SUCCESS": 1, "FAILURE": 99999, "SET_STIFFNESS_FAILED": -1, "SET_DAMPING_FAILED": -2,
        "SET_MAX_CARTESIAN_VELOCITY_FAILED": -3, "SET_MAX_CONTROL_FORCE_FAILED": -4,
        "SET_MAX_PATH_DEVIATION": -5, "SET_NULL_SPACE_PARAMETERS_FAILED": -6,
        "SET_CARTESIAN_CONTROL_FAILED": -7, "TIMED_OUT": -8, "PREEMPTED": -9, "NO_VALID_LOAD_DATA_SET": -10,
    },
}


@pytest.mark.parametrize("cls", list(MD5), ids=lambda c: c._type)
def test_md5sum_matches_original(cls):
    assert cls._md5sum == MD5[cls]


@pytest.mark.parametrize("cls", list(FIELDS), ids=lambda c: c._type)
def test_fields_in_original_order(cls):
    assert list(zip(cls.__slots__, cls._slot_types, strict=True)) == FIELDS[cls]


@pytest.mark.parametrize("cls", list(CONSTANTS), ids=lambda c: c._type)
def test_constants(cls):
    assert {name: getattr(cls, name) for name in CONSTANTS[cls]} == CONSTANTS[cls]


def test_control_law_constants_declared_in_original_order():
    text = msg.ControlLaw._full_text
    names = ("TYPE_UNKNOWN", "TYPE_FOLLOWER", "TYPE_COMPLIANT_MOVE", "TYPE_SPRING")
    order = [text.index(name) for name in names]
    assert order == sorted(order)


def test_rossrv_show_matches_spec():
    if shutil.which("rossrv") is None:
        pytest.skip("rossrv not on PATH")
    out = subprocess.run(
        ["rossrv", "show", "cartesian_impedance_msgs/ConfigureForceControl"],
        capture_output=True, text=True, check=True,
    ).stdout
    request, response = out.split("---")
    top_level = [line for line in request.splitlines() if line and not line.startswith(" ")]
    assert top_level == [
        "cartesian_impedance_msgs/SetCartesianImpedance cart_impedance_params",
        "cartesian_impedance_msgs/SetCartesianForceCtrl cart_force_control",
        "cartesian_impedance_msgs/DirectionControlLaws direction_control_laws",
    ]
    assert "  geometry_msgs/Wrench set" in request.replace("    ", "  ")
    assert [line for line in response.splitlines() if line and not line.startswith(" ")] == [
        "bool success",
        "cartesian_impedance_msgs/CartesianForceCtrlErrorCodes error",
    ]
