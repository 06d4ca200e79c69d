"""A real driver's interface on top of a :class:`~mujoco_driver.sim.Simulation` (no ROS: the node adapts it).

:class:`DriverEmulation` holds the profile's controller manager, wrench model and reflex, and computes from
the simulation's state what the driver publishes: the wrench in the driver's frame and convention, and the
tf transforms the driver provides. The node calls :meth:`DriverEmulation.update` under its simulation lock
at every publication and asks :meth:`DriverEmulation.refusal` before passing a command on.
"""

from __future__ import annotations

import mujoco
import numpy as np

from mujoco_driver.controllers import ControllerManager, SwitchResult
from mujoco_driver.profiles import DriverProfile, ProfileError
from mujoco_driver.protective_stop import ProtectiveStop
from mujoco_driver.sim import Simulation
from mujoco_driver.wrench_models import Reflex, WrenchModel, change_frame, gravity_wrench, set_payload_weight

__all__ = ["DriverEmulation"]


class DriverEmulation:
    """The profile's behaviour on one simulation.

    Args:
        sim: The simulation (the caller serialises access, as for every Simulation call).
        profile: The resolved profile.

    Raises:
        ProfileError: If a link the profile names is not in the robot description.
    """

    def __init__(self, sim: Simulation, profile: DriverProfile) -> None:
        self.sim, self.profile = sim, profile
        model = sim.model
        missing = sorted(name for name in profile.links()
                         if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) < 0)
        if missing:
            raise ProfileError(f"driver profile {profile.driver}: links {missing} are not in the robot "
                               "description")
        self._body = {name: model.body(name).id for name in profile.links()}
        self.controllers = ControllerManager(profile.controllers, sim.arm_joint_names)
        self.model = WrenchModel(profile.wrench, len(sim.joint_names), 1.0 / profile.publish_rate)
        self.reflex = Reflex(profile.reflex.force_thresholds) if profile.reflex else None
        # The joints for the reflex's robot state message (ros_emulation), taken with each update.
        with_state = profile.reflex is not None and profile.reflex.state is not None
        self.state_q, self.state_dq = np.zeros(len(sim.qpos)), np.zeros(len(sim.qpos))
        self._with_state = with_state
        stop = profile.protective_stop
        self.stop = ProtectiveStop(stop.force_limit, stop.unlock_after) if stop else None
        self.wrench = np.zeros(6)  # what the driver publishes [N, Nm]
        spec = profile.wrench
        self._payload_error = spec.payload_mass_error != 0.0 or any(spec.payload_com_error)
        # The wrench frame's Jacobian (world axes, all dofs), computed only for a torque model error.
        self._jac = (np.zeros((3, model.nv)), np.zeros((3, model.nv))) if spec.torque_error else None
        # Per tf entry: translation [m] and quaternion (x, y, z, w) of child in parent.
        self.transforms = [(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])) for _ in profile.tf]
        self._quat = np.zeros(4)

    def _pose(self, link: str) -> tuple[np.ndarray, np.ndarray]:
        data, body = self.sim.data, self._body[link]
        return data.xmat[body].reshape(3, 3), data.xpos[body]

    def _jacobian(self, r_f: np.ndarray) -> np.ndarray | None:
        """The wrench frame's Jacobian (6 x joints: linear rows of its origin, in its axes), if needed."""
        if self._jac is None:
            return None
        (jacp, jacr), sim = self._jac, self.sim
        mujoco.mj_jacBody(sim.model, sim.data, jacp, jacr, self._body[self.profile.wrench.frame_link])
        dofs = sim.scene.dof_adr
        return np.vstack([r_f.T @ jacp[:, dofs], r_f.T @ jacr[:, dofs]])

    def update(self, sensor: np.ndarray) -> bool:
        """Compute the published wrench and transforms from the current state.

        Args:
            sensor: The simulated sensor's reading (``Simulation.wrench``), sensor frame.

        Returns:
            True when this wrench tripped the reflex or the protective stop (the arm is then held where it
            is).
        """
        sim, data, scene = self.sim, self.sim.data, self.sim.scene
        r_s = data.site_xmat[scene.ft_site].reshape(3, 3)
        p_s = data.site_xpos[scene.ft_site]
        r_f, p_f = self._pose(self.profile.wrench.frame_link)
        in_frame = change_frame(sensor, r_s, p_s, r_f, p_f)
        mass, com = sim.model.body_subtreemass[scene.sensor_body], data.subtree_com[scene.sensor_body]
        gravity = sim.model.opt.gravity
        weight = gravity_wrench(mass, com, p_f, r_f, gravity)
        payload = None
        if self._payload_error:
            payload = set_payload_weight(self.profile.wrench, mass, com, p_f, r_f, gravity)
        self.wrench[:] = self.model(in_frame, weight, sim.qpos, self._jacobian(r_f), payload)
        for (pos, quat), spec in zip(self.transforms, self.profile.tf, strict=True):
            r_p, p_p = self._pose(spec.parent_link)
            r_c, p_c = self._pose(spec.child_link)
            pos[:] = r_p.T @ (p_c - p_p)
            mujoco.mju_mat2Quat(self._quat, (r_p.T @ r_c).ravel())
            quat[:] = self._quat[1], self._quat[2], self._quat[3], self._quat[0]
        if self._with_state:
            self.state_q[:], self.state_dq[:] = sim.qpos, sim.qvel
        if (self.reflex is not None and self.reflex.check(self.wrench)) or \
                (self.stop is not None and self.stop.check(self.wrench, sim.time)):
            sim.set_position_targets(sim.qpos)
            return True
        return False

    def refusal(self, controller: str) -> str:
        """Why a command to ``controller`` does not move the arm now ("" = it does)."""
        if self.reflex is not None and self.reflex.tripped:
            assert self.profile.reflex is not None  # self.reflex is made from it
            return (f"the robot stopped in a reflex ({self.reflex.reason}): call "
                    f"{self.profile.reflex.recovery_action}")
        stop, spec = self.stop, self.profile.protective_stop
        if stop is not None and spec is not None and not stop.program_running:
            if stop.reason:
                return f"{stop.reason}: call {spec.unlock_service}, then {spec.play_services[0]}"
            return f"the robot program is not running: call {spec.play_services[0]}"
        if not self.controllers.accepts(controller):
            state = self.controllers.state(controller)
            return (f"controller {controller} is {state} (running: {self.controllers.running()}); switch it "
                    f"on with {self.profile.controller_manager}/switch_controller")
        return ""

    def switch(self, start: list[str], stop: list[str], strictness: int) -> SwitchResult:
        """Switch controllers; a stopped command controller stops the arm (its last command ends)."""
        result = self.controllers.switch(start, stop, strictness)
        if result.ok and result.stopped and self.sim.mode == "velocity":
            self.sim.set_velocity_targets(np.zeros(len(self.sim.joint_names)))
        elif result.ok and result.stopped and self.sim.mode == "trajectory":
            self.sim.set_position_targets(self.sim.qpos)
        return result

    def recover(self) -> bool:
        """Error recovery: clear the reflex, hold the current position; True if there was one."""
        if self.reflex is None or not self.reflex.recover():
            return False
        self.sim.set_position_targets(self.sim.qpos)
        return True

    def unlock(self) -> tuple[bool, str]:
        """The dashboard's unlock_protective_stop: (success, answer); the arm holds where it is."""
        assert self.stop is not None  # the service exists only with a protective stop
        self.sim.set_position_targets(self.sim.qpos)
        return self.stop.unlock(self.sim.time)

    def play(self) -> tuple[bool, str]:
        """resend_robot_program / dashboard play: (success, answer); the arm holds until a command."""
        assert self.stop is not None
        self.sim.set_position_targets(self.sim.qpos)
        return self.stop.play()

    def reset_stops(self) -> bool:
        """After the simulation's reset: no reflex, no protective stop; True if there was either."""
        stopped = self.stop is not None and (bool(self.stop.reason) or not self.stop.program_running)
        if self.stop is not None:
            self.stop.reset()
        return self.recover() or stopped

    def zero(self) -> None:
        """Zero the published wrench at its current value (the driver's zero_ftsensor)."""
        self.model.zero(self.wrench)
