"""A cell: several arms in one MuJoCo world, stepped together (README, *Cells*).

Each arm is built as it is alone (its URDF, its scene settings with its own table and fixtures) and placed in
the world at its base pose, its names prefixed with its own (``left/``). Each is then a
:class:`~mujoco_driver.sim.Simulation` bound to the shared model and data: its commands, joints, wrench and
poses are its own, in its own base frame, and what one arm does reaches the others only through the physics.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from mujoco_driver.config import SceneConfig
from mujoco_driver.scene import SceneError, arm_spec, index_scene, rpy_to_quat
from mujoco_driver.sim import Simulation, step_arms

__all__ = ["CellArm", "World"]


@dataclass(frozen=True)
class CellArm:
    """One arm of a cell.

    Attributes:
        name: Its name in the cell (the robot's namespace): a prefix of its MuJoCo names, ``name/``.
        urdf: Its robot description.
        scene: Its scene settings (its table and fixtures come along, in its base frame).
        position: Its base frame's origin in the world [m].
        rpy: Its base frame's orientation in the world [rad].
    """

    name: str
    urdf: str
    scene: SceneConfig
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


class World:
    """The arms of a cell in one MuJoCo world; `arms[name]` is each one's :class:`Simulation`.

    Raises:
        SceneError: No arm, two of one name, arms whose time steps or integrators differ, or an arm's own
            scene error (named).
    """

    def __init__(self, arms: Sequence[CellArm], mesh_cache: str | None = None) -> None:
        if not arms:
            raise SceneError("a cell needs at least one arm")
        names = [a.name for a in arms]
        if len(set(names)) != len(names) or not all(names) or any("/" in n for n in names):
            raise SceneError(f"cell arms need distinct names without '/', got {names}")
        first = arms[0].scene
        for arm in arms[1:]:
            if (arm.scene.timestep, arm.scene.integrator) != (first.timestep, first.integrator):
                raise SceneError(f"arm {arm.name}: timestep {arm.scene.timestep} s / {arm.scene.integrator} "
                                 f"differs from {arms[0].name}'s {first.timestep} s / {first.integrator}: "
                                 "one world steps them all at once")
        placed = []  # (arm, its spec, its base pose: x, y, z, qw, qx, qy, qz)
        for arm in arms:
            try:
                spec = arm_spec(arm.urdf, arm.scene, mesh_cache)
            except SceneError as exc:
                raise SceneError(f"arm {arm.name}: {exc}") from None
            base = np.concatenate((np.asarray(arm.position, float), rpy_to_quat(arm.rpy)))
            placed.append((arm, spec, base))
        world = mujoco.MjSpec()
        world.option.timestep = placed[0][1].spec.option.timestep
        world.option.integrator = placed[0][1].spec.option.integrator
        for arm, spec, base in placed:
            frame = world.worldbody.add_frame(pos=base[:3], quat=base[3:])
            world.attach(spec.spec, prefix=f"{arm.name}/", frame=frame)
        try:
            self.model = world.compile()
        except ValueError as exc:
            raise SceneError(f"MuJoCo cannot compile the cell: {exc}") from exc
        self.data = mujoco.MjData(self.model)
        self.arms: dict[str, Simulation] = {}
        for arm, spec, base in placed:
            scene = index_scene(self.model, spec, f"{arm.name}/")
            self.arms[arm.name] = Simulation.in_world(self, arm.scene, scene, base)
        self._arms = list(self.arms.values())
        self.reset()

    @property
    def dt(self) -> float:
        """The world's timestep [s]."""
        return float(self.model.opt.timestep)

    @property
    def time(self) -> float:
        """Simulated time since the last :meth:`reset` [s]."""
        return float(self.data.time)

    def reset(self) -> None:
        """Every arm back to its start pose at time 0, at rest, holding position; fixtures at rest."""
        mujoco.mj_resetData(self.model, self.data)
        for arm in self._arms:
            arm._reset_arm()
        mujoco.mj_forward(self.model, self.data)
        for arm in self._arms:
            arm._write_controls()
        mujoco.mj_forward(self.model, self.data)

    def step(self, n: int = 1) -> None:
        """Advance every arm ``n`` timesteps, each following its own command."""
        step_arms(self.model, self.data, self._arms, n)
