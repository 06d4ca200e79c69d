"""Key map and teleop logic without ROS: every key, speeds and their bounds, the deadman, the stop key."""

from __future__ import annotations

import math
import pathlib
import re

import pytest
from keyboard_publisher.keymap import AXIS_NAMES, KEYMAP, Action, key_code, key_label, render_help
from keyboard_publisher.teleop import (
    MIN_SPEED_FRACTION,
    PARAMETERS,
    ZERO,
    TeleopSettings,
    TeleopSettingsError,
    TeleopState,
)

README = pathlib.Path(__file__).resolve().parents[2] / "src" / "keyboard_publisher" / "README.md"

# key, twist index, sign: the documented map (the original's w/s/d/a first).
MOTION_ROWS = [
    ("w", 0, +1), ("s", 0, -1), ("d", 1, +1), ("a", 1, -1),
    ("r", 2, +1), ("f", 2, -1),
    ("i", 3, +1), ("k", 3, -1), ("l", 4, +1), ("j", 4, -1), ("u", 5, +1), ("o", 5, -1),
    ("up", 0, +1), ("down", 0, -1), ("right", 1, +1), ("left", 1, -1),
    ("page_up", 2, +1), ("page_down", 2, -1),
]  # fmt: skip


def state(**overrides) -> TeleopState:
    return TeleopState(TeleopSettings(**overrides))


@pytest.mark.parametrize(("key", "axis", "sign"), MOTION_ROWS)
def test_each_motion_key_moves_one_axis_at_the_current_speed(key, axis, sign):
    teleop = state()
    result = teleop.press(key, 0.0)
    assert result.publish_now
    expected = [0.0] * 6
    expected[axis] = sign * (0.2 if axis < 3 else 0.3)
    assert teleop.tick(0.0) == tuple(expected)


def test_map_has_no_gaps_and_no_stray_motion_keys():
    letters = {(b.axis, b.sign): k for k, b in KEYMAP.items() if b.action is Action.MOTION and len(k) == 1}
    assert set(letters) == {(axis, sign) for axis in range(6) for sign in (1, -1)}
    documented = {key for key, _, _ in MOTION_ROWS}
    assert {k for k, b in KEYMAP.items() if b.action is Action.MOTION} == documented
    # Speed and stop keys do not shadow any motion key.
    assert {k for k, b in KEYMAP.items() if b.action is not Action.MOTION}.isdisjoint(documented)


def test_stop_key_sends_zero_at_once_then_repeats_and_goes_quiet():
    teleop = state(key_timeout=100.0, stop_repeats=3)
    teleop.press("w", 0.0)
    assert teleop.tick(0.01)[0] == pytest.approx(0.2)
    result = teleop.press("x", 0.02)
    assert result.publish_now and result.binding.action is Action.STOP
    assert [teleop.tick(0.02 + 0.02 * n) for n in range(5)] == [ZERO, ZERO, ZERO, None, None]
    assert teleop.press(" ", 1.0).publish_now  # space stops too
    assert teleop.tick(1.0) == ZERO


def test_deadman_zero_after_key_timeout_without_presses():
    teleop = state(key_timeout=0.6, stop_repeats=2)
    teleop.press("w", 0.0)
    assert teleop.tick(0.59)[0] == pytest.approx(0.2)
    assert teleop.command(0.59)[0] == pytest.approx(0.2)
    assert teleop.command(0.6) == ZERO
    assert [teleop.tick(t) for t in (0.6, 0.62, 0.64, 5.0)] == [ZERO, ZERO, None, None]


def test_held_key_repeats_keep_moving_past_the_timeout():
    teleop = state(key_timeout=0.6)
    for n in range(60):  # 2 s of auto-repeat at 30 Hz
        teleop.press("w", n / 30.0)
        assert teleop.tick(n / 30.0 + 0.01)[0] == pytest.approx(0.2)
    assert not teleop.press("w", 2.0).publish_now  # a repeat is not a new command


def test_a_released_held_key_stops_after_repeat_timeout_not_key_timeout():
    """A real hold: first press, the terminal's 0.5 s repeat delay, then repeats at 30 Hz for 1.5 s."""
    teleop = state(key_timeout=0.6, repeat_timeout=0.15)
    presses = [0.0] + [0.5 + n / 30.0 for n in range(46)]
    for t in presses:
        teleop.press("w", t)
    last = presses[-1]
    # Moving all along: the first gap (the repeat delay) is bridged by key_timeout ...
    assert all(teleop.command(t)[0] == pytest.approx(0.2) for t in (0.3, 0.49, 1.0, last + 0.14))
    # ... and after the release the twist stops 0.15 s after the last repeat: 30 mm at 0.2 m/s, not 120.
    assert teleop.command(last + 0.151) == ZERO


def test_a_single_tap_moves_for_key_timeout():
    teleop = state(key_timeout=0.6, repeat_timeout=0.15)
    teleop.press("w", 0.0)
    assert teleop.command(0.59)[0] == pytest.approx(0.2)
    assert teleop.command(0.6) == ZERO
    teleop.press("w", 1.0)  # a new tap after the stop is a first press again: key_timeout
    assert teleop.command(1.5)[0] == pytest.approx(0.2)


def test_repeat_timeout_above_key_timeout_is_refused():
    with pytest.raises(TeleopSettingsError, match="repeat_timeout"):
        TeleopSettings(key_timeout=0.3, repeat_timeout=0.5)


def test_new_motion_key_replaces_the_command():
    teleop = state()
    teleop.press("w", 0.0)
    assert teleop.press("d", 0.1).publish_now
    assert teleop.tick(0.1) == (0.0, 0.2, 0.0, 0.0, 0.0, 0.0)


def test_unknown_keys_are_ignored_and_do_not_extend_the_deadman():
    teleop = state(key_timeout=0.6)
    teleop.press("w", 0.0)
    result = teleop.press("p", 0.5)
    assert result.binding is None and not result.publish_now
    assert teleop.tick(0.7) == ZERO


@pytest.mark.parametrize(
    ("up", "down", "attr", "initial", "limit", "axis_key", "axis"),
    [
        ("t", "g", "linear_speed", 0.2, "max_linear_speed", "w", 0),
        ("y", "h", "angular_speed", 0.3, "max_angular_speed", "u", 5),
    ],
)
def test_speed_keys_step_multiplicatively_within_bounds(up, down, attr, initial, limit, axis_key, axis):
    teleop = state(speed_step=1.25)
    top = getattr(teleop.settings, limit)
    other = "angular_speed" if attr == "linear_speed" else "linear_speed"
    other_before = getattr(teleop, other)
    assert teleop.press(up, 0.0).speeds_changed
    assert getattr(teleop, attr) == pytest.approx(initial * 1.25)
    for n in range(40):
        teleop.press(up, 0.01 * n)
    assert getattr(teleop, attr) == pytest.approx(top)
    assert not teleop.press(up, 1.0).speeds_changed  # at the bound: nothing changes
    teleop.press(axis_key, 1.0)
    assert abs(teleop.tick(1.0)[axis]) == pytest.approx(top)  # the twist uses the new speed
    for n in range(100):
        teleop.press(down, 2.0 + 0.01 * n)
    assert getattr(teleop, attr) == pytest.approx(MIN_SPEED_FRACTION * top)
    assert getattr(teleop, other) == other_before  # the other speed is untouched


def test_speed_change_while_moving_rescales_the_twist():
    teleop = state(key_timeout=10.0, speed_step=2.0, max_linear_speed=1.0)
    teleop.press("s", 0.0)
    teleop.press("t", 0.1)
    assert teleop.tick(0.2)[0] == pytest.approx(-0.4)


def test_release_is_reported_once_when_another_key_comes_or_after_the_timeout():
    teleop = state(key_timeout=0.6)
    assert teleop.press("w", 0.0).released is None
    assert teleop.press("w", 0.03).released is None
    assert teleop.press("d", 0.06).released == "w"
    assert teleop.release(0.5) is None
    assert teleop.release(0.7) == "d"
    assert teleop.release(0.8) is None


def test_quit_keys_are_ctrl_c_and_ctrl_d():
    teleop = state()
    for key in ("\x03", "\x04"):
        assert teleop.press(key, 0.0).binding.action is Action.QUIT


def test_bad_press_is_refused_and_state_unchanged():
    teleop = state(key_timeout=0.6)
    teleop.press("w", 0.0)
    with pytest.raises(TypeError):
        teleop.press(119, 0.1)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="finite"):
        teleop.press("s", math.nan)
    assert teleop.tick(0.2)[0] == pytest.approx(0.2)


def test_key_codes_are_x11_keysyms():
    assert key_code("w") == ord("w") == 119
    assert key_code(" ") == 32
    assert key_code("up") == 0xFF52
    assert key_code("escape") == 0xFF1B
    assert key_code("\U0001f600") == 0  # does not fit uint16


def test_help_lists_every_key_and_the_speeds():
    text = render_help(0.2, 0.3, 0.5, 1.0, 0.6, 1.1)
    for key in KEYMAP:
        assert re.search(rf"(^|\s){re.escape(key_label(key))}(\s|$)", text, re.M), key
    for name in AXIS_NAMES:
        assert name in text
    assert "linear 0.200 m/s (max 0.500)" in text
    assert "angular 0.300 rad/s (max 1.000)" in text


def readme_keys_table() -> list[tuple[list[str], str]]:
    """Rows of the README keys table: (keys of the first cell, meaning)."""
    text = README.read_text()
    section = text[text.index("## Keys") :]
    section = section[: section.index("\n## ", 1)]
    rows = []
    for line in section.splitlines():
        cells = line.split("|")
        if line.startswith("| `"):
            rows.append((re.findall(r"`([^`]+)`", cells[1]), cells[2].strip()))
    return rows


def test_readme_keys_table_matches_the_key_map():
    by_label = {key_label(key): key for key in KEYMAP}
    documented: set[str] = set()
    for labels, meaning in readme_keys_table():
        keys = [by_label[label] for label in labels]  # KeyError: the README names a key the map lacks
        documented.update(keys)
        bindings = [KEYMAP[key] for key in keys]
        axis = next((n for n, name in enumerate(AXIS_NAMES) if meaning.startswith(name + " ")), None)
        if axis is not None:
            assert [(b.action, b.axis, b.sign) for b in bindings] == [
                (Action.MOTION, axis, +1), (Action.MOTION, axis, -1)
            ], labels
        elif meaning.startswith("stop"):
            assert all(b.action is Action.STOP for b in bindings), labels
        elif meaning.startswith(("linear speed", "angular speed")):
            action = Action.LINEAR_SPEED if meaning.startswith("linear") else Action.ANGULAR_SPEED
            assert [(b.action, b.sign) for b in bindings] == [(action, +1), (action, -1)], labels
        else:
            assert meaning.startswith("quit") and all(b.action is Action.QUIT for b in bindings), labels
    assert documented == set(KEYMAP), "keys missing from the README keys table"


def test_readme_documents_every_parameter_with_its_default():
    text = README.read_text()
    for name, declared in PARAMETERS.items():
        default, unit = declared.default, declared.unit
        row = next((line for line in text.splitlines() if line.startswith(f"| `~{name}` |")), None)
        assert row is not None, name
        cells = [cell.strip() for cell in row.split("|")]
        assert cells[2].strip("`\"") == str(default).strip('"'), name
        assert cells[3] == unit, name


@pytest.mark.parametrize(
    ("params", "key"),
    [
        ({"linear_speed": -0.1}, "linear_speed"),
        ({"linear_speed": 0.6}, "linear_speed"),  # above max_linear_speed 0.5
        ({"angular_speed": 0.001}, "angular_speed"),  # below 1 % of the max
        ({"max_angular_speed": math.inf}, "max_angular_speed"),
        ({"rate": 0}, "rate"),
        ({"rate": 5000.0}, "rate"),
        ({"key_timeout": math.nan}, "key_timeout"),
        ({"speed_step": 1.0}, "speed_step"),
        ({"speed_step": "fast"}, "speed_step"),
        ({"stop_repeats": 0}, "stop_repeats"),
        ({"stop_repeats": True}, "stop_repeats"),
        ({"topic": ""}, "topic"),
        ({"frame_id": 3}, "frame_id"),
    ],
)
def test_bad_parameters_are_refused_naming_the_key(params, key):
    with pytest.raises(TeleopSettingsError, match=f"'~{key}'") as err:
        TeleopSettings.from_params(params)
    assert err.value.key == key


def test_parameters_load_with_defaults_ints_and_warnings():
    settings, warnings = TeleopSettings.from_params({"rate": 20, "frame_id": "tool0"})
    assert settings.rate == 20.0 and isinstance(settings.rate, float)
    assert settings.frame_id == "tool0"
    assert settings.topic == "jog_arm_server/delta_jog_cmds"
    assert settings.linear_speed == 0.2
    assert warnings == []
    expected = "~key_timout is not a parameter: did you mean ~key_timeout"
    with pytest.raises(TeleopSettingsError, match=expected):
        TeleopSettings.from_params({"rate": 20, "key_timout": 1.0})
    _, warnings = TeleopSettings.from_params({"key_timeout": 0.3})
    assert any("repeat delay" in w for w in warnings)
