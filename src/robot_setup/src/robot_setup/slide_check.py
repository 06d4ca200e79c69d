"""Does the simulated arm slide its tool cleanly over the block? make robot presses the tool on the block and
slides it as surface following does, in MuJoCo alone (mujoco_driver's Simulation, jog_arm's kinematics; no
ROS master, no contact_control), and lowers the servo gains until the contact force stays steady (robot_setup
README, *What make robot decides*).

Why: at the effort rule's gains (kp 4200 Nm/rad on 35 Nm joints) the SO-100's tool chattered on the block at
MuJoCo's 2 ms step (contacts 0-4, 3 % of steps none; force std 2.3 N, 3-13 N): the surface-following demo's 50
ms means reached 11.5-11.75 N of 10 +- 1.5. The same slide at a 0.5 ms step gave 0.5 N: the step does not
resolve the stiff servo on the light arm against the block. The committed robot packages slide at 0.05-0.21 N;
two larger generated arms chattered at 2.2-2.5 N and slide cleanly at x0.64-0.8 (robot_setup README). The
chatter is not monotonic in the gain (SO-100: clean at x0.25-0.30 and x0.476, chattering at x0.36-0.44 and
x0.5-1.0; x0.41 clean or not with a 0.5 s longer settle), so a gain is taken only when 0.9 and 0.8 of it are
clean too: in the middle of a clean band.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from jog_arm.kinematics import ArmModel
from mujoco_driver.sim import Simulation

from robot_setup.tip_response import joint_rates

__all__ = ["CHATTER_STD", "SCALES", "SlideResult", "servo_scale", "slide_force_std"]

CHATTER_STD = 0.5  # [N] the sliding force's std above which the tool chatters (a fitted number: see above)
SCALES = (1.0, 0.8, 0.64, 0.51, 0.41, 0.33, 0.26, 0.21)  # kp and kv factors tried, in this order
PRESS_FORCE = 10.0  # [N] surface following's target
SLIDE_SPEED = 0.01  # [m/s] surface following's X speed
_APPROACH = 0.01  # [m/s] down to the block
_B = 2000.0  # [N/(m/s)] the press's force loop: V = (F - target) / b on a ~8 Hz low-pass of the force
_LOW_PASS = 0.1  # per 2 ms step
_SETTLE, _SLIDE, _SKIP = 1.0, 2.5, 0.5  # [s] pressed before sliding, sliding, left out at its start


class SlideResult:
    """One slide: the contact force's std while sliding [N] (NaN: never pressed), and its mean."""

    def __init__(self, std: float, mean: float) -> None:
        self.std, self.mean = std, mean

    @property
    def clean(self) -> bool:
        return bool(self.std <= CHATTER_STD)


def slide_force_std(
    urdf_xml: str, scene: Mapping[str, Any], joints: Sequence[str], direction: float, scale: float = 1.0
) -> SlideResult:
    """Presses the tool from the start pose down on the block with PRESS_FORCE, then slides it SLIDE_SPEED
    along the base's X (`direction`'s sign); the contact force (base Z, tool weight out) while sliding.
    `scale` multiplies the scene's servo kp and kv."""
    cfg = dict(scene)
    servo = dict(cfg["servo"])
    servo["kp"] = {k: v * scale for k, v in servo["kp"].items()}
    servo["kv"] = {k: v * scale for k, v in servo["kv"].items()}
    cfg["servo"] = servo
    sim = Simulation(urdf_xml, cfg)
    held = {name: float(value) for item in cfg.get("held_joints") or () for name, value in item.items()}
    arm = ArmModel(urdf_xml, "tool_tip", joint_names=list(joints), held_positions=held)
    start = cfg["start_pose"]
    q0 = np.array([float(start.get(n, 0.0)) for n in sim.joint_names])
    sim.data.qpos[sim.scene.qpos_adr] = q0
    sim.set_position_targets(q0)
    arm_index = np.array([sim.joint_names.index(n) for n in arm.joint_names])
    sim.step(round(0.5 / sim.dt))

    def force_z() -> float:
        return float((sim.sensor_rotation() @ sim.wrench()[:3])[2])

    weight = force_z()
    filtered, pressed_at, slide_at = 0.0, -1.0, -1.0
    seen: list[float] = []
    obstacle = cfg["obstacle"]
    top = float(obstacle["position"][2]) + 0.5 * float(obstacle["size"][2])  # the block's top, base z [m]
    # Down to the top at the approach speed, four times over, then the press, settle and slide with margin.
    deadline = sim.time + 4.0 * (float(sim.eef_pose()[0][2]) - top) / _APPROACH + 30.0
    while sim.time < deadline:
        force = force_z() - weight
        filtered += (force - filtered) * _LOW_PASS
        vz = -_APPROACH if filtered < 0.5 * PRESS_FORCE else (filtered - PRESS_FORCE) / _B
        if pressed_at < 0.0 and filtered > 0.9 * PRESS_FORCE:
            pressed_at = sim.time
        if slide_at < 0.0 <= pressed_at and sim.time - pressed_at >= _SETTLE:
            slide_at = sim.time
        vx = 0.0
        if slide_at >= 0.0:
            since = sim.time - slide_at
            if since >= _SLIDE:
                break
            vx = float(np.copysign(SLIDE_SPEED, direction))
            if since >= _SKIP:
                seen.append(force)
        sim.set_arm_velocity_targets(joint_rates(arm, sim.qpos[arm_index], (vx, 0.0, vz)))
        sim.step()
    if not seen:
        return SlideResult(float("nan"), float("nan"))
    return SlideResult(float(np.std(seen)), float(np.mean(seen)))


def servo_scale(
    urdf_xml: str, scene: Mapping[str, Any], joints: Sequence[str], direction: float, kp_min: float
) -> tuple[float, SlideResult, SlideResult]:
    """The largest of SCALES at which the slide is clean and 0.9 and 0.8 of it too, no kp below `kp_min`;
    with the slide at the effort rule's gains and at the scale taken. (1.0, ...) when clean as given or when
    no scale is (the package keeps its gains; the caller says so)."""
    first = slide_force_std(urdf_xml, scene, joints, direction)
    if first.clean or math.isnan(first.std):
        return 1.0, first, first
    least = min(scene["servo"]["kp"].values())
    for scale in SCALES[1:]:
        if least * scale < kp_min:
            break
        result = slide_force_std(urdf_xml, scene, joints, direction, scale)
        if result.clean and all(slide_force_std(urdf_xml, scene, joints, direction, f * scale).clean
                                for f in (0.9, 0.8)):
            return scale, first, result
    return 1.0, first, first
