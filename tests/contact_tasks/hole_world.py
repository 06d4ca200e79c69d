"""A pure closed loop for task tests: contact_control's controller drives an ideal arm holding a square peg
over a plate with a square, chamfered hole (no ROS, no simulator).

The plate's top is z = 0 (fixed frame, z up); the peg's tip is the end effector's position. Contact is a
stiff spring: on the plate the surface pushes up; on the 45-degree chamfer it pushes up and towards the
hole's centre alike; inside, the walls push back beyond the clearance and the bottom pushes up. A
Coulomb-like friction opposes sliding on the plate.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from contact_control.request import validate_laws_request
from contact_tasks.run import Command, Observation, TaskRun

from contact_control import ContactControl, load_settings

DT = 0.002  # [s] contact_control's cycle
PEG_HALF = 0.005  # [m] a 10 mm square peg


@dataclass
class HoleWorld:
    hole: tuple[float, float] = (0.0, 0.0)  # [m] the hole's true centre
    clearance: float = 0.0004  # [m] hole width minus peg width
    chamfer: float = 0.001  # [m] width (and depth) of the 45-degree chamfer
    depth: float = 0.02  # [m]
    stiffness: float = 20000.0  # [N/m] of the plate, chamfer and walls
    friction: float = 0.2  # Coulomb coefficient on the plate
    last: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def wrench(self, pose: np.ndarray) -> tuple[float, ...]:
        """The wrench on the tool (the surface's push, as the sensor reads it) at `pose`."""
        p = pose[:3, 3]
        e = p[:2] - np.asarray(self.hole)
        half_gap = self.clearance / 2.0
        inside = bool(np.all(np.abs(e) <= half_gap))
        in_hole = p[2] < -self.chamfer  # below the chamfer the peg can only be in the hole
        force = np.zeros(3)
        towards = np.zeros(2)
        if in_hole or inside:  # the walls hold the peg within the clearance; the bottom below
            for i in range(2):
                over = abs(e[i]) - half_gap
                if over > 0.0:
                    force[i] = -math.copysign(self.stiffness * over, e[i])
            floor = -self.depth
        else:  # the highest point of plate or chamfer under the peg's edges
            floor = -self.chamfer
            for i in range(2):
                drop = half_gap + self.chamfer - abs(e[i])
                if drop <= 0.0:  # this edge is on the plate
                    floor, towards = 0.0, np.zeros(2)
                    break
                height = -min(drop, self.chamfer)
                if height > floor:
                    floor = height
                if drop < self.chamfer:  # this edge rests on the chamfer
                    towards[i] = -math.copysign(1.0, e[i])
        press = floor - p[2]
        if press > 0.0:
            force[2] += self.stiffness * press
            if floor < 0.0 and not (in_hole or inside):  # on the chamfer: towards the centre
                force[:2] += self.stiffness * press * towards
            elif floor == 0.0:  # sliding on the plate
                slide = p[:2] - self.last[:2]
                speed = float(np.linalg.norm(slide)) / DT
                if speed > 1e-5:
                    scale = self.friction * force[2] * min(speed / 1e-3, 1.0)  # Coulomb, smoothed near rest
                    force[:2] -= scale * slide / np.linalg.norm(slide)
        self.last = p.copy()
        return (float(force[0]), float(force[1]), float(force[2]), 0.0, 0.0, 0.0)


class TaskLoop:
    """A task run against the world: every cycle the controller updates and the tool moves as commanded; the
    executor sees what contact_control's status and events would say, every `observe_every` cycles."""

    def __init__(self, run: TaskRun, world: HoleWorld, start: np.ndarray, observe_every: int = 5,
                 **params: object) -> None:
        settings = {"tare_on_startup": False, "event_touch_force": 3.0, **params}
        self.ctrl = ContactControl(load_settings(settings))
        self.run, self.world = run, world
        self.pose = start.copy()
        self.t = 0.0
        self.every = observe_every
        self.trace: list[tuple[float, float, float, float, float]] = []  # t, x, y, z, fz
        self.commands: list[Command] = []
        self._touched = False
        self._was_touching = False
        self._tool_axes = False  # the laws act along the tool's axes (a request's frame), not the plate's
        #: Called with the run and each observation after the run's update (a test's own measurements).
        self.watch: Callable[[TaskRun, Observation], None] | None = None
        #: From this time on the robot is stopped by its driver (held; jog_arm's ~robot_stop says `stop_why`).
        self.stop_at, self.stop_why = math.inf, "the robot stopped: a protective stop"

    def _apply(self, command: Command) -> None:
        self.commands.append(command)
        if command.reference is not None:
            r = command.reference
            self.ctrl.set_path_reference(r.position, r.quaternion, r.twist, self.t, r.horizon, r.horizon_step)
        if command.laws is not None:
            self._tool_axes = bool(getattr(command.laws, "frame", ""))
            if command.restart:
                self.ctrl.stop("the next step")
            self.ctrl.set_laws(validate_laws_request(command.laws), self.pose, self.t)
        if command.stop:
            self.ctrl.stop("the task ended")

    def go(self, seconds: float) -> Command:
        wrench = self.world.wrench(self.pose)
        command = self.run.start(self._observe(wrench, True))
        self._apply(command)
        cycle = 0
        while self.run.running and self.t < seconds:
            if self._tool_axes:  # as contact_control's stage turns them: sensor (plate axes) into the tool's
                R = self.pose[:3, :3]
                T_cs = np.eye(4)
                T_cs[:3, :3] = R.T
                result = self.ctrl.update(wrench, self.t, T_cs.tolist(), None, self.pose, R.tolist())
                linear = R @ np.asarray(result.velocity[:3])
            else:
                result = self.ctrl.update(wrench, self.t, eef_pose=self.pose)
                linear = np.asarray(result.velocity[:3])
            touching = math.sqrt(sum(f * f for f in result.wrench[:3])) >= 3.0
            self._touched |= touching and not self._was_touching
            self._was_touching = touching
            if self.t < self.stop_at:  # held by the driver after it
                self.pose[:3, 3] += linear * DT
            self.t += DT
            wrench = self.world.wrench(self.pose)
            self.trace.append((self.t, *self.pose[:3, 3], wrench[2]))
            cycle += 1
            if cycle % self.every == 0:
                obs = self._observe(result.wrench, result.move_active)
                command = self.run.update(obs)
                if self.watch is not None:
                    self.watch(self.run, obs)
                self._apply(command)
        return command

    def _observe(self, wrench: object, active: bool) -> Observation:
        touched, self._touched = self._touched, False
        stop = self.stop_why if self.t >= self.stop_at else ""
        return Observation(self.t, self.pose.copy(), tuple(wrench), active, "", touched,  # type: ignore[arg-type]
                           robot_stop=stop)


def tool_down(x: float, y: float, z: float) -> np.ndarray:
    """The tool pointing down (its z along -z of the base) at (x, y, z)."""
    pose = np.diag([1.0, -1.0, -1.0, 1.0])
    pose[:3, 3] = (x, y, z)
    return pose
