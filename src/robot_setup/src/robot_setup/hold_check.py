"""Can the simulated arm stand at its start pose and reach its named poses? `make check-robot` (and make
robot's own check) holds the arm at sim.yaml's start pose under the tool's weight and moves it to each pose of
named_poses.yaml and back, in MuJoCo alone (mujoco_driver's Simulation, its servos as the driver runs them; no
ROS), and names the joint that ends farther off than named_poses' goal tolerance, or the link of the arm that
rests on the table or the obstacle there (robot_setup README, *What make robot decides*).

Why: an arm whose servos cannot carry it (weak efforts in the URDF, heavy links) passed the kinematic checks
and then stopped `make demo` before its first demonstration ("named pose 'start' failed: did not reach
'start': largest joint error 0.510 rad").
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from mujoco_driver.sim import Simulation

__all__ = ["HOLD_TIME", "hold_problems"]

HOLD_TIME = 2.0  # [s] held at each pose after its move's planned end (named_poses' settle_time is 3 s)
_SATURATED = 0.99  # of the URDF effort: the servo gives all it has


def _worst(sim: Simulation, goal: np.ndarray) -> tuple[int, float]:
    error = np.abs(sim.qpos - goal)
    i = int(np.argmax(error))
    return i, float(error[i])


def _touching(sim: Simulation) -> list[str]:
    """The pairs of bodies in contact now (the arm pushed off its pose by a part of the robot, the table)."""
    model, data = sim.scene.model, sim.data
    pairs = {tuple(sorted((model.body(model.geom_bodyid[c.geom1]).name or "world",
                           model.body(model.geom_bodyid[c.geom2]).name or "world")))
             for c in data.contact[:data.ncon]}
    return [f"{a} / {b}" for a, b in sorted(pairs)]


def _resting(sim: Simulation) -> list[str]:
    """The links the arm's joints move (not the tool's; not a held base's wheels on the floor; not the first
    link, which turns on the base on the table: a collision mesh of it may reach into the table) touching the
    table or the obstacle now. The start pose search sees the table but not the block placed under the tool
    after it; a forearm resting on the block drags on it in every demonstration (a rail arm's follower
    drifted 2.4 mm sideways so, its replay and peg in hole failed)."""
    model, data = sim.scene.model, sim.data
    tool = sim.scene.sensor_body
    parents = model.body_parentid
    arm_bodies = {int(model.jnt_bodyid[model.joint(n).id]) for n in sim.arm_joint_names}
    first = min(arm_bodies)  # bodies are numbered parents first

    def below(b: int, roots: set[int]) -> bool:
        while b > 0:
            if b in roots:
                return True
            b = int(parents[b])
        return False

    links = set()
    for c in data.contact[:data.ncon]:
        a, b = int(model.geom_bodyid[c.geom1]), int(model.geom_bodyid[c.geom2])
        if c.dist < 0.0 and 0 in (a, b):
            link = b if a == 0 else a
            if link and link != first and below(link, arm_bodies) and not below(link, {tool}):
                links.add(model.body(link).name)
    return sorted(links)


def _why(sim: Simulation, i: int, kp: float) -> str:
    """Why a joint did not get there: a contact pushing the arm, or its servo's torque against the URDF's
    effort."""
    touching = _touching(sim)
    if touching:
        return f"the simulated arm touches {', '.join(touching)} there (the scene collides what the start " \
               "pose search let touch)"
    model = sim.scene.model
    joint = model.joint(sim.joint_names[i]).id  # MuJoCo's URDF reader limits its actuator force to the effort
    limit = float(model.jnt_actfrcrange[joint][1]) if model.jnt_actfrclimited[joint] else np.inf
    effort = float(abs(sim.effort[i]))
    if np.isfinite(limit) and effort >= _SATURATED * limit:
        return f"its servo is at the URDF's effort limit, {limit:g} Nm: the arm is too heavy for it"
    return f"its servo pushes {effort:.1f} Nm of {limit:g} Nm with kp {kp:g} (sim.yaml servo.kp)"


def hold_problems(urdf_xml: str, scene: Mapping[str, Any], poses: Mapping[str, Mapping[str, float]],
                  tolerance: float) -> list[str]:
    """The start pose held for HOLD_TIME, then each named pose reached (at the URDF's velocity limits) and
    held for HOLD_TIME, then the start again; a problem for the first pose the arm ends more than
    `tolerance` [rad] off."""
    sim = Simulation(urdf_xml, scene)  # at the start pose, holding it
    start = sim.qpos.copy()
    kp = scene.get("servo", {}).get("kp", {})
    problems = []
    goals = [("start", start)]
    for name, pose in poses.items():
        goal = start.copy()
        for joint, value in pose.items():
            if joint in sim.joint_names:
                goal[sim.joint_names.index(joint)] = float(value)
        goals += [(name, goal), ("start", start)]
    seen = set()
    for name, goal in goals:
        if name == "start" and "start" in seen:
            continue
        sim.set_position_targets(goal)
        travel = float(np.max(np.abs(goal - sim.qpos) / sim.scene.velocity_limit))
        sim.step(round((travel + HOLD_TIME) / sim.dt))
        resting = _resting(sim) if name == "start" else []
        if resting:
            problems.append(f"start pose: the simulated arm's {', '.join(resting)} rests on the table or the "
                            "obstacle there (the demonstrations would drag it along)")
            break
        i, error = _worst(sim, goal)
        if error > tolerance:
            joint = sim.joint_names[i]
            gain = kp.get(joint, kp) if isinstance(kp, Mapping) else kp
            problems.append(f"named pose {name!r}: the simulated arm ends {error:.3f} rad off at {joint} "
                            f"(named_poses' goal tolerance {tolerance:g} rad): {_why(sim, i, float(gain))}")
            break  # the arm is off: the poses after would say the same
        seen.add(name)
    return problems
