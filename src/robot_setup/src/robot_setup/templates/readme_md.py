# ruff: noqa: E501  (the template is the file's text: Markdown tables keep their long lines)
"""README.md: how to run the package, its files, the start pose analysis and, for a driver profile, the real robot.

It names the whole command, `DRIVER=` included: `recorded_command` reads it back from here.
"""

from __future__ import annotations

from robot_setup.plan import Plan, command_line
from robot_setup.templates.driver_text import frame_origin, model_words
from robot_setup.templates.text import generated_by, num

__all__ = ["readme_md"]


def readme_md(plan: Plan, analysis: list[str]) -> str:
    """`analysis`: the start pose analysis, in the lines `make robot` printed."""
    d = plan.driver
    name = plan.spec.name
    pkg = f"{name}_custom"
    generated_all = generated_by(plan.spec)
    analysis_text = "\n".join(analysis)
    if d.generic:
        hardware_row = (
            "| `config/*_hardware.yaml`, `launch/hardware.launch` | the same for a real arm with a generic ros_control "
            "driver (tested against `emulated_robot.launch` without a profile); set your drivers' topics |"
        )
        real_robot = ""
    else:
        hardware_row = (
            f"| `config/*_hardware.yaml`, `launch/hardware.launch` | the same for a real arm driven by {d.driver} "
            f"(mujoco_driver's `{d.profile}` profile; tested against `emulated_robot.launch profile:={d.profile}`): "
            "see *Real robot* |"
        )
        real_robot = _real_robot(plan)
    return f"""# {pkg}

Configuration of the {name} for the compliant-control stack, {generated_all}: the stock URDF
(`{plan.source}`{', without ' + ', '.join(plan.removed) if plan.removed else ''}) + a wrist F/T sensor frame on
`{plan.spec.tip}` + a {num(plan.spec.tool_mass)} kg tool, the MuJoCo scene, contact_control, jog_arm and named-pose
settings, the demonstrations' geometry, and launch files. Only YAML and launch files; regenerate with the
same command (the same files come out), check with `make check-robot ROBOT={name}`.

```bash
scripts/with_env roslaunch {pkg} sim.launch            # headless; viewer:=true for a window
scripts/with_env roslaunch {pkg} sim.launch viewer:=rviz   # RViz on config/view.rviz (compliant_rviz)
make demo ROBOT={name}                                  # the seven demonstrations
scripts/with_env rosservice call /named_poses/move_to "{{name: home}}"
```

## Look and tune

```bash
scripts/with_env roslaunch {pkg} sim.launch viewer:=rviz                 # RViz: the robot, wrench, laws, velocity
scripts/with_env rosrun compliant_common show_diagnostics --detail           # every node's health, worst first
scripts/with_env rosrun dynamic_reconfigure dynparam get /contact_control_node   # what can change live
scripts/with_env rosrun dynamic_reconfigure dynparam set /contact_control_node max_velocity 0.05
scripts/with_env rosrun dynamic_reconfigure dynparam set /jog_arm_server scale/linear 0.2
```
(hardware.launch takes viewer:=rviz too; the tunable parameters and how a refused value is answered:
contact_control's and jog_arm's READMEs.)

## Files

| file | what |
|---|---|
| `config/description.args` | `make_description` arguments: stock URDF, sensor frame `ft_sensor` on `{plan.spec.tip}`, tool, tip `tool_tip` |
| `config/sim.yaml` | MuJoCo scene: table, obstacle under the tool, start pose (found by `make robot`), servo gains from the URDF efforts |
| `config/demos.yaml` | the demonstrations' directions and distances, scaled to the reach (~{plan.reach:.2f} m) |
| `config/named_poses.yaml` | `start` (= the scene's start pose) and `home` (the tool lifted) for `/named_poses/move_to` |
| `config/contact_control.yaml`, `config/jog_arm.yaml` | the stack on top of its defaults: frames (`{plan.base}`), tool mass and COM, thresholds |
{hardware_row}
| `config/view.rviz` | RViz's view for viewer:=rviz (compliant_rviz) |
| `launch/sim.launch`, `launch/keyboard.launch` | the simulated stack; keyboard jogging |

## Start pose analysis (printed by `make robot`)

Tool pointing down over the table; jog_arm's condition number (linear Jacobian rows divided by
`singularity_length_scale` 0.4 m); margins to the joint limits (continuous joints have none):

```
{analysis_text}
```

`singularity_threshold` is 1.2 x the worst condition number on the demos' motions, so jog_arm never slows
them; `hard_stop_singularity_threshold` is at least 12 (the hand-written packages' value).

{real_robot}## What the simulation lacks

Joint friction and motor dynamics beyond a servo with armature, the real controller's limits, a real F/T
sensor's drift and bias; the servo gains come from the URDF's efforts, not from the robot's controller.
"""


def _real_robot(plan: Plan) -> str:
    """The README's *Real robot* section for a driver profile."""
    d = plan.driver
    command = command_line(plan.spec)
    name = plan.spec.name
    pkg = f"{name}_custom"
    mass = num(plan.spec.tool_mass)
    model = model_words(d)
    payload = (f" with the tool ({mass} kg, centre of mass 0.05 m out from the flange) set as the payload "
               "configured on the robot" if d.payload_compensated else "")
    if d.switch_needed:
        stop = ", ".join(d.stop_for_jog)
        back = ""
        if d.trajectory_controller in d.stop_for_jog:
            back = (f" named_poses' `move_to` needs {d.trajectory_controller} running: switch back for it (the "
                    "same call with the lists exchanged).")
        step3 = (
            f"3. Switch jog_arm's controller on (the driver starts {d.jog_controller} {d.jog_initial_state}; until "
            "the switch, jog_arm's commands are ignored and the arm does not move):\n"
            f"   `rosservice call /{d.controller_manager}/switch_controller \"{{start_controllers: "
            f"[{d.jog_controller}], stop_controllers: [{stop}], strictness: 2}}\"`.{back}\n"
        )
    else:
        step3 = f"3. No controller switch: {d.jog_controller} runs from the start.\n"
    mass_value = "0 (and `tool_com` 0)" if d.payload_compensated else f"{mass} kg"
    sign_value = "-1 (all three)" if d.wrench_sign < 0 else "1 (the default)"
    zero = f" `{d.zero_service}` (std_srvs/Trigger) zeroes the driver's wrench." if d.zero_service else ""
    return f"""## Real robot ({d.driver})

`{command}` wrote the hardware files for {d.driver} from mujoco_driver's `{d.profile}`
driver profile (its default options): the profile's topics, wrench frame and convention, rate and controllers.
Not run on a real {name} here; run unchanged against mujoco_driver's emulation of {d.driver} by
`tests/robot_packages/test_robot_emulated_drivers.py`, in these steps (step 1 is the only one that differs on
the cell):

1. Start the driver. On the cell: {d.driver}'s bringup for your robot{payload}. Emulated:
   `roslaunch mujoco_driver emulated_robot.launch robot_package:={pkg} profile:={d.profile}`.
2. `roslaunch {pkg} hardware.launch` (unchanged, no arguments).
{step3}4. Jog (`keyboard.launch hardware:=true`, or TwistStamped on `/jog_arm_server/delta_jog_cmds`, `{plan.base}`,
   m/s) and use contact control (`/configure_cartesian_impedance`): the test jogs 2 cm along -X, then a follower
   (b = 200 N s/m) on X and then Y gives way to 10 N pushes (`/mujoco_driver/push` in the emulation, a hand on
   the cell).

What the profile set (`config/*_hardware.yaml`, `launch/hardware.launch`):

| setting | value | profile key |
|---|---|---|
| jog_arm `joint_topic`, named_poses' and robot_state_publisher's joint states | `{d.joint_states_topic}` | `joint_states_topic` |
| contact_control `ft_in_topic` | `{d.wrench_topic}` | `wrench.topic` |
| contact_control `ft_sensor_frame` | `{d.wrench_frame}` ({frame_origin(d)}) | `wrench.frame`, `tf` |
| contact_control `tool_mass` | {mass_value} | `wrench.model: {d.wrench_model}` ({model}) |
| contact_control `ft_x/y/z_direction` | {sign_value} | `wrench.sign: {d.wrench_sign}` |
| contact_control `lp_filter_delta_t`, jog_arm `joint_state_timeout` | {num(round(1.0 / d.rate, 4))} s, {d.state_timeout:g} s | `publish_rate: {d.rate:g}` [Hz] |
| jog_arm `cmd_out_topic`, `command_out_type` | `{d.jog_topic}`, `{d.jog_command_type}` | the `command: {d.jog_command}` controller (velocity preferred, then running) |
| named_poses `trajectory_topic` | `{d.trajectory_topic}` | a `command: trajectory` controller (running preferred) |
| step 3 | {'switch' if d.switch_needed else 'none'} | that controller's `initial_state: {d.jog_initial_state}` |

The profile's links ({', '.join(sorted(d.links))}) are in this description (`make robot` checks it: the emulated
driver refuses a description without them).{zero} The driver's own bringup may run a robot_state_publisher on
the stock URDF: give it this description instead and pass `with_state_publisher:=false` to hardware.launch, or
the arm's links get two tf publishers.

"""
