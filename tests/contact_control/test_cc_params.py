"""Settings: the original keys load, defaults are the fork's numbers, bad values are refused by key."""

import pytest
from contact_control.params import PARAMETERS, ContactControlSettings, ParamError, load_settings

# The original Panda conf file (SPEC section 5), nested under contact_control: as the original YAML was.
ORIGINAL_PANDA = {
    "contact_control": {
        "ft_in_topic": "wrench",
        "velocity_out_topic": "/ee_velocity",
        "move_group": "panda_arm",
        "fixed_frame": "panda_link0",
        "velocity_command_frame": "panda_link0",
        "ft_sensor_frame": "panda_link0",
        "control_frame": "panda_link0",
        "lp_filter_enabled": True,
        "lp_filter_delta_t": 0.2,
        "lp_filter_cutoff_freq": 0.6,
        "ft_x_direction": -1,
        "ft_y_direction": 1,
        "ft_z_direction": 1,
        "travel_x_direction": 1,
        "travel_y_direction": 1,
        "travel_z_direction": -1,
        "global_max_force": 25.0,
        "global_max_torque": 25.0,
        "max_velocity": 0.25,
    }
}


def test_original_yaml_loads_unchanged():
    s = load_settings(ORIGINAL_PANDA)
    assert s.move_group == "panda_arm" and s.control_frame == "panda_link0"
    assert s.ft_directions == (-1, 1, 1) and s.travel_directions == (1, 1, -1)
    assert s.lp_filter_delta_t == 0.2 and s.max_velocity == 0.25


def test_defaults_are_the_fork_numbers():
    s = load_settings({})
    lin, ang = s.tuning(False), s.tuning(True)
    assert (lin.deadband, lin.min_velocity, lin.deceleration) == (2.5, 0.005, 2.5)
    assert (ang.deadband, ang.min_velocity) == (2.5, 0.005)
    assert lin.deceleration * 0.002 == pytest.approx(0.005)  # 0.005 m/s per cycle at 500 Hz
    assert (s.spring_output_scale, s.spring_rounding, s.compliant_slowdown_distance) == (0.2, 0.01, 0.02)
    assert ang.max_velocity == s.max_velocity  # unset max_angular_velocity: one clamp for all
    assert s.control_rate == 500.0


def test_top_level_keys_win_over_nested_and_unknown_keys_refuse_start_up():
    s = load_settings({"contact_control": {"max_velocity": 0.1}, "max_velocity": 0.2})
    assert s.max_velocity == 0.2
    typo = "global_max_forse is not a parameter: did you mean global_max_force"
    with pytest.raises(ParamError, match=typo):
        load_settings({"global_max_forse": 30.0})
    with pytest.raises(ParamError, match="old_key is not a parameter: see the package README"):
        load_settings({"contact_control": {"old_key": 1}})


def test_every_parameter_is_a_settings_field_with_the_same_default():
    defaults = ContactControlSettings()
    for p in PARAMETERS.values():
        assert getattr(defaults, p.name) == p.default, p.name


BAD = [  # (params, key named in the error)
    ({"max_velocity": -0.1}, "max_velocity"),
    ({"max_velocity": "fast"}, "max_velocity"),
    ({"global_max_force": 0}, "global_max_force"),
    ({"ft_x_direction": 2}, "ft_x_direction"),
    ({"travel_z_direction": 0}, "travel_z_direction"),
    ({"lp_filter_enabled": "yes"}, "lp_filter_enabled"),
    ({"lp_filter_delta_t": 1.0, "lp_filter_cutoff_freq": 0.6}, "lp_filter_cutoff_freq"),  # above Nyquist
    ({"tool_com": [0, 0]}, "tool_com"),
    ({"tool_mass": float("nan")}, "tool_mass"),
    ({"bias": [0, 0, 0, 0, 0, "x"]}, "bias"),
    ({"min_velocity_linear": 0.3}, "min_velocity_linear"),  # not below the 0.25 m/s clamp
    ({"compliant_approach_speed_linear": 0.004}, "compliant_approach_speed_linear"),  # would stall
    ({"no_data_end_timeout": 0.05}, "no_data_end_timeout"),
    ({"ft_in_topic": 5}, "ft_in_topic"),
    ({"contact_control": "nope"}, "contact_control"),
]


@pytest.mark.parametrize(("params", "key"), BAD)
def test_bad_values_are_refused_naming_the_key(params, key):
    with pytest.raises(ParamError) as err:
        load_settings(params)
    assert err.value.key == key
    assert key in str(err.value)
