"""Programs (teach.program, teach.simplify, teach.recorder): simplification within the tolerance at each
sample's time, keyframes kept, a YAML round trip, refusals that name what to change."""

from __future__ import annotations

import math

import numpy as np
import pytest
from teach.program import Program, ProgramError, ProgramStore, check_name
from teach.recorder import Recorder
from teach.simplify import interpolate, quaternion_angle, simplify, slerp

JOINTS = ("j1", "j2")


def l_path(n_per_leg: int = 250, dt: float = 0.02, noise: float = 0.0002):
    """A hand-guided L: 10 cm along X then 5 cm along Y, smooth speed profiles, 0.2 mm of tremor."""
    s = np.linspace(0.0, 1.0, n_per_leg)
    ease = 3 * s**2 - 2 * s**3
    x = np.concatenate([0.1 * ease, np.full(n_per_leg, 0.1)])
    y = np.concatenate([np.zeros(n_per_leg), 0.05 * ease])
    p = np.stack([x, y, np.full(2 * n_per_leg, 0.3)], axis=1)
    p += np.random.default_rng(7).normal(0.0, noise, p.shape)
    angle = np.linspace(0.0, math.radians(20.0), 2 * n_per_leg)  # the tool turns 20 degrees about Z
    q = np.stack([np.zeros_like(angle), np.zeros_like(angle), np.sin(angle / 2), np.cos(angle / 2)], axis=1)
    return np.arange(2 * n_per_leg) * dt, p, q


def test_simplify_keeps_every_sample_within_the_tolerance_at_its_time_with_few_waypoints():
    t, p, q = l_path()
    kept = simplify(t, p, q, position_tolerance=0.001, angle_tolerance=math.radians(1.0))
    assert kept[0] == 0 and kept[-1] == len(t) - 1
    assert len(kept) < len(t) / 10, len(kept)
    worst_p = worst_a = 0.0
    for ti, pi, qi in zip(t, p, q, strict=True):
        pos, quat, _ = interpolate(t[kept], p[kept], q[kept], ti)
        worst_p = max(worst_p, float(np.linalg.norm(pos - pi)))
        worst_a = max(worst_a, quaternion_angle(quat, qi))
    assert worst_p <= 0.001 and worst_a <= math.radians(1.0)
    coarse = simplify(t, p, q, position_tolerance=0.005, angle_tolerance=math.radians(5.0))
    assert len(coarse) < len(kept)  # a looser tolerance, fewer waypoints


def test_simplify_keeps_keyframes_and_a_pause_in_time():
    t, p, q = l_path(noise=0.0)
    keep = [False] * len(t)
    keep[100] = True
    assert 100 in simplify(t, p, q, keep)
    # Standing still for 2 s then moving on: the stop is kept (time matters, not only the path).
    t2 = np.concatenate([t[:250], t[250:] + 2.0])
    kept = simplify(t2, p, q)
    pos, _, _ = interpolate(t2[kept], p[kept], q[kept], t2[249] + 1.0)
    assert np.linalg.norm(pos - p[249]) <= 0.001


def test_slerp_takes_the_short_way_and_ends_where_asked():
    a = (0.0, 0.0, 0.0, 1.0)
    b = (0.0, 0.0, -math.sin(0.5), -math.cos(0.5))  # the same rotation as +1 rad about Z, other sign
    mid = slerp(a, b, 0.5)
    assert quaternion_angle(mid, (0.0, 0.0, math.sin(0.25), math.cos(0.25))) < 1e-9
    assert quaternion_angle(slerp(a, b, 1.0), b) < 1e-9


def recorded(name: str = "l_path", keys: tuple[int, ...] = (120,)) -> Program:
    rec = Recorder("ur5", "base_link", "tool_tip", 50.0, 0.001, math.radians(1.0))
    t, p, q = l_path()
    rec.start(name, 100.0)
    for i, (ti, pi, qi) in enumerate(zip(t, p, q, strict=True)):
        if i in keys:
            rec.keyframe()
        rec.add(100.0 + ti, JOINTS, (0.1 * i, -0.2), pi, qi, (0.0, 0.0, 1.0 + i * 0.01, 0.0, 0.0, 0.0))
    return rec.finish()


def test_a_recording_becomes_a_program_that_round_trips_through_yaml(tmp_path):
    program = recorded()
    assert program.samples == 500 and 2 < len(program.waypoints) < 50
    assert program.waypoints[0].t == 0.0 and program.duration == pytest.approx(9.98)
    assert [i for i, w in enumerate(program.waypoints) if w.keyframe] and program.length == pytest.approx(
        0.15, abs=0.01)
    store = ProgramStore(str(tmp_path / "programs"))
    path = store.save(program)
    text = open(path).read()
    assert text.startswith("# Program 'l_path' taught by hand on ur5") and "waypoints:" in text
    again = store.load("l_path")
    assert again.name == program.name and again.robot == "ur5" and again.joint_names == JOINTS
    assert len(again.waypoints) == len(program.waypoints)
    for a, b in zip(again.waypoints, program.waypoints, strict=True):
        assert a.keyframe == b.keyframe and np.allclose(a.position, b.position, atol=1e-6)
        assert np.allclose(a.orientation, b.orientation, atol=1e-6) and a.t == pytest.approx(b.t, abs=1e-4)
    assert store.names() == ["l_path"]
    with pytest.raises(ProgramError, match="exists"):
        store.save(program)
    store.delete("l_path")
    assert store.names() == []
    with pytest.raises(ProgramError, match="no program 'l_path'"):
        store.load("l_path")


def test_samples_keep_their_poses_times_and_a_pose_seen_again_is_dropped():
    """The node samples the newest tf at a fixed rate and passes the pose's own stamp: on a busy machine the
    same pose comes twice or an older one late; kept, they would make the path's speed jump."""
    rec = Recorder("ur5", "base_link", "tool_tip", 50.0, 0.001, math.radians(1.0))
    rec.start("stamps", 10.0)
    stream = ((9.99, 0.0), (10.01, 0.001), (10.01, 0.001), (10.005, 0.0005), (10.03, 0.003), (10.05, 0.005))
    for t, x in stream:
        rec.add(t, JOINTS, (0.0, 0.0), (x, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), (0.0,) * 6)
    assert rec.count == 4  # the repeated 10.01 and the late 10.005 dropped
    program = rec.finish()
    assert program.waypoints[0].t == 0.0  # from the first pose, which was older than the start call
    assert program.duration == pytest.approx(0.06)
    assert program.length == pytest.approx(0.005)


def test_a_program_of_another_robot_or_joints_is_refused_with_the_reason():
    program = recorded()
    program.check_robot("ur5", JOINTS)
    with pytest.raises(ProgramError, match="recorded on robot 'ur5', this is 'panda'"):
        program.check_robot("panda", JOINTS)
    with pytest.raises(ProgramError, match="has joints"):
        program.check_robot("ur5", ("a", "b"))


@pytest.mark.parametrize("bad", ["", "../x", "a b", "x" * 65, ".hidden"])
def test_bad_names_are_refused(bad):
    with pytest.raises(ProgramError, match="program name"):
        check_name(bad)


def test_recorder_refusals_change_nothing(tmp_path):
    rec = Recorder("ur5", "base_link", "tool_tip", 50.0, 0.001, 0.0175)
    with pytest.raises(ProgramError, match="not recording"):
        rec.keyframe()
    with pytest.raises(ProgramError, match="not recording"):
        rec.finish()
    rec.start("a", 0.0)
    with pytest.raises(ProgramError, match="already recording 'a'"):
        rec.start("b", 1.0)
    rec.add(0.1, JOINTS, (0, 0), (0, 0, 0), (0, 0, 0, 1), (0,) * 6)
    with pytest.raises(ProgramError, match="1 sample"):
        rec.finish()
    assert not rec.recording


def test_malformed_files_are_refused_naming_the_problem(tmp_path):
    store = ProgramStore(str(tmp_path))
    (tmp_path / "bad.yaml").write_text("format: 1\nname: bad\n")
    with pytest.raises(ProgramError, match="missing or malformed field"):
        store.load("bad")
    data = recorded().to_dict()
    data["waypoints"][1]["t"] = -1.0
    with pytest.raises(ProgramError, match="back in time"):
        Program.from_dict(data)
    data = recorded().to_dict()
    data["format"] = 2
    with pytest.raises(ProgramError, match="format 2"):
        Program.from_dict(data)


def test_playback_follows_the_waypoints_in_time_and_its_clock_pauses_and_slows():
    from teach.playback import Playback, path_distance

    program = recorded()
    play = Playback(program, speed=2.0)
    assert play.duration == pytest.approx(program.duration)
    play.advance(1.0)  # 1 s of replay at 2x: 2 s of the program
    p, _, twist = play.reference()
    assert play.time == pytest.approx(2.0) and p[0] > program.waypoints[0].position[0]
    play.paused = True
    play.advance(1.0)
    assert play.time == pytest.approx(2.0) and not np.any(play.reference()[2])  # held, no velocity
    play.paused = False
    play.advance(1.0, rate=0.5)  # slowed for the arm: half the clock, half the fed-forward velocity
    assert play.time == pytest.approx(3.0)
    assert np.linalg.norm(play.reference()[2][:3]) < np.linalg.norm(twist[:3])
    play.advance(100.0)
    assert play.done and play.progress == 1.0 and not np.any(play.reference()[2])
    path = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.05, 0.0]])
    d = path_distance(np.array([[0.05, 0.002, 0.0], [0.103, 0.02, 0.0], [0.2, 0.0, 0.0]]), path)
    assert d == pytest.approx([0.002, 0.003, 0.1])


def test_the_horizon_is_where_the_reference_will_be_and_holds_while_paused_and_at_the_end():
    from teach.playback import Playback

    play = Playback(recorded(), speed=2.0)
    play.advance(1.0, rate=0.5)
    ahead = play.horizon(0.1, 4)
    for j, (p, q) in enumerate(ahead, start=1):
        later = Playback(recorded(), speed=2.0)
        later.advance(1.0 + j * 0.1, rate=0.5)  # the same clock, on at the same rate
        p_ref, q_ref, _ = later.reference()
        assert p == pytest.approx(p_ref) and q == pytest.approx(q_ref)
    assert ahead[-1][0][0] > ahead[0][0][0]  # it moves on along the first leg
    play.paused = True
    assert all(p == pytest.approx(play.reference()[0]) for p, _ in play.horizon(0.1, 4))
    play.paused = False
    play.advance(100.0)
    assert all(p == pytest.approx(play.reference()[0]) for p, _ in play.horizon(0.1, 4))


def test_a_replay_faster_than_the_arm_is_slowed_to_its_limits_before_it_starts():
    from teach.playback import Playback
    from teach.timing import Limits, replay_times

    program = recorded()  # the L: up to ~15 mm/s along X, ~23 degrees/s about Z at 1x
    limits = Limits(velocity=0.03, acceleration=0.05, deceleration=0.1, angular_velocity=0.5,
                    angular_acceleration=5.0, angular_deceleration=5.0)
    free = Playback(program, speed=4.0)
    assert free.planned == pytest.approx(program.duration / 4.0)
    play = Playback(program, speed=4.0, limits=limits)
    assert program.duration / 4.0 < play.planned < program.duration
    deltas = play._deltas
    for timing, within in ((replay_times(free._t, deltas, 4.0, Limits()), False), (play._r, True)):
        v = deltas / np.diff(timing)[:, None]
        rest = np.zeros((1, 6))
        change = np.diff(np.vstack([rest, v, rest]), axis=0)[:, :3]  # at each waypoint
        half = np.diff(timing) / 2
        over = np.concatenate(([half[0]], half[:-1] + half[1:], [half[-1]]))
        speeding = np.abs(np.vstack([v, rest])[:, :3]) > np.abs(np.vstack([rest, v])[:, :3])
        acc = np.abs(change) / over[:, None]
        ok = np.all(np.abs(v[:, :3]) <= 0.03 + 1e-9) and np.all(acc[speeding] <= 0.05 * 1.001) and np.all(
            acc[~speeding] <= 0.1 * 1.001)
        assert ok == within  # 4x asks more than the arm gives; the plan does not
    # The same path, its timing stretched: at the same program time, the same pose.
    play.clock = play.planned * 0.37
    at_once = Playback(program, 1.0)
    at_once.clock = play.time
    assert np.allclose(at_once.reference()[0], play.reference()[0])
    # The fed-forward twist stays within the velocity limit all along.
    while not play.done:
        assert np.abs(play.reference()[2][:3]).max() <= 0.03 + 1e-9
        play.advance(0.01)
    slow = Playback(program, speed=0.5, limits=limits)  # within every limit: as asked
    assert slow.planned == pytest.approx(program.duration / 0.5)


def test_the_fed_forward_velocity_ramps_instead_of_stepping_and_still_covers_the_path():
    from teach.playback import Playback

    program = recorded()
    dt = 0.005
    steps = {}
    for smoothing in (0.0, 0.1):
        play = Playback(program, 2.0, smoothing=smoothing)
        twists = []
        while not play.done:
            twists.append(play.reference()[2].copy())
            play.advance(dt)
        twists = np.array(twists)
        steps[smoothing] = np.abs(np.diff(twists[:, :3], axis=0)).max()
        # Integrated, the velocity goes where the path goes (to within a sample period's worth).
        moved = twists[:, :3].sum(axis=0) * dt
        path = np.array(program.waypoints[-1].position) - np.array(program.waypoints[0].position)
        assert np.allclose(moved, path, atol=0.002), (smoothing, moved, path)
    assert steps[0.1] < steps[0.0] / 5, steps  # a step at a waypoint becomes a ramp over 0.2 s


def test_a_faster_replay_is_never_planned_much_slower_than_a_slower_one():
    """A hand-taught L (accelerations already at the arm's 0.4 m/s^2): 2 x and 4 x are slowed to the arm,
    but not below 1 x (stretching each waypoint's two segments fully at once compounded: 2 x planned 2.48 s,
    1 x 2.18 s)."""
    import pathlib

    import yaml
    from teach.playback import Playback
    from teach.timing import Limits

    data = yaml.safe_load((pathlib.Path(__file__).parent / "data" / "taught_l_jaco2.yaml").read_text())
    program = Program.from_dict(data)
    limits = Limits(0.25, 0.4, 0.4, 0.5, 2.5, 2.5)  # a robot package's contact_control limits
    planned = {s: Playback(program, s, limits).planned for s in (0.5, 1.0, 2.0, 4.0)}
    assert planned[0.5] == pytest.approx(2 * (program.duration - program.waypoints[0].t))  # within limits
    assert planned[4.0] <= planned[2.0] * 1.02 and planned[2.0] <= planned[1.0] * 1.02, planned
    assert planned[2.0] > program.duration / 2  # ... but slowed: 2 x of it is beyond the arm
