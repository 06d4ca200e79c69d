"""Does the arm touch itself or the table at a configuration? MuJoCo's own collision check on the scene the
simulation builds (mujoco_driver.scene), so a start pose the generator accepts does not collide there.

Pure: mujoco and numpy, no ROS. Pairs of bodies at most `KIN_HOPS` apart in the kinematic tree are
ignored (neighbouring links' meshes overlap at their joints by design), and so are pairs that the arm's
joints do not move (the base on the table, a held mobile base's wheels on the floor) and pairs the scene
itself leaves out (links overlapping in every posture: `mujoco_driver.scene`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import mujoco
import numpy as np
from mujoco_driver.scene import build_scene

from mujoco_driver.config import SceneConfig

__all__ = ["CollisionChecker"]

KIN_HOPS = 3  # e.g. tool -> sensor -> flange -> last wrist link: these may touch
CLEARANCE = 0.005  # [m] closer than this counts as touching


class CollisionChecker:
    """Contacts of the robot with itself and the table at given joint angles.

    Args:
        urdf_xml: The description (with sensor and tool).
        joint_names: The order of the angles given to :meth:`contacts`.
        inside: Angles within every joint's limits (the scene needs a valid start pose); default zeros.
        held: Positions of the joints that are not in `joint_names` (the scene's held joints).
    """

    def __init__(
        self, urdf_xml: str, joint_names: Sequence[str], inside: Sequence[float] | np.ndarray | None = None,
        held: Mapping[str, float] | None = None,
    ) -> None:
        # Any configuration within the limits will do for building the scene (`inside`, default all zero).
        start = dict(zip(joint_names, inside, strict=True)) if inside is not None else 0.0
        cfg = SceneConfig.from_dict({"start_pose": start, "servo": {"kp": 1.0, "kv": 0.0},
                                     "held_joints": dict(held or {})})
        scene = build_scene(urdf_xml, cfg)
        self.model = scene.model
        self.data = mujoco.MjData(self.model)
        by_name = dict(zip(scene.joint_names, scene.qpos_adr, strict=True))
        for name, value in (held or {}).items():
            self.data.qpos[by_name[name]] = value
        self._adr = [int(by_name[j]) for j in joint_names]
        m = self.model
        # Bodies the given joints move: a pair of bodies that none of them moves (the base on the table, a
        # held torso's wheels on the floor) touches alike in every configuration and is ignored.
        moving_joints = {m.joint(j).id for j in joint_names}
        self._moving = np.zeros(m.nbody, dtype=bool)
        for b in range(1, m.nbody):
            own = any(m.body_jntadr[b] <= jid < m.body_jntadr[b] + m.body_jntnum[b] for jid in moving_joints)
            self._moving[b] = own or self._moving[m.body_parentid[b]]
        m.geom_margin[:] = CLEARANCE
        depth = np.zeros(m.nbody, dtype=int)
        for b in range(1, m.nbody):
            depth[b] = depth[m.body_parentid[b]] + 1
        self._depth = depth

    def _hops(self, a: int, b: int) -> int:
        parent, depth = self.model.body_parentid, self._depth
        hops = 0
        while a != b:
            if depth[a] >= depth[b]:
                a = parent[a]
            else:
                b = parent[b]
            hops += 1
        return hops

    def contacts(self, q: Sequence[float] | np.ndarray) -> list[str]:
        """'body_a / body_b' for each pair touching (within CLEARANCE) at joint angles `q`; empty: none."""
        m, d = self.model, self.data
        for adr, value in zip(self._adr, q, strict=True):
            d.qpos[adr] = value
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        out = []
        for i in range(d.ncon):
            con = d.contact[i]
            if con.dist > CLEARANCE:
                continue
            a, b = m.geom_bodyid[con.geom1], m.geom_bodyid[con.geom2]
            if not (self._moving[a] or self._moving[b]):
                continue
            if self._hops(int(a), int(b)) <= KIN_HOPS:
                continue
            names = sorted((mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, a) or "world",
                            mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) or "world"))
            label = f"{names[0]} / {names[1]}"
            if label not in out:
                out.append(label)
        return out
