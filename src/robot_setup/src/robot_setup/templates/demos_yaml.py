# ruff: noqa: E501  (the template is the file's text: its comment lines keep their length)
"""config/demos.yaml: the thesis demonstrations' directions and distances, scaled to the arm's reach."""

from __future__ import annotations

from robot_setup.plan import Plan
from robot_setup.sensor_limits import contact_force_for
from robot_setup.templates.text import generated_by, num

__all__ = ["demos_yaml"]


def demos_yaml(plan: Plan) -> str:
    name = plan.spec.name
    g = plan.geometry
    d = plan.driver
    generated = generated_by(plan.spec, with_driver=False)
    direction = "toward the base" if g.hybrid_direction < 0 else "away from the base"
    text = f"""# The four thesis demonstrations on the {name}: directions and distances (read by thesis_demos' run_demos,
# `make demo ROBOT={name}`); {generated}. Scaled to the arm's tool-tip reach (~{plan.reach:.2f} m; thesis-sized
# from 0.9 m). Directions are signs along the base frame's axes. The obstacle is in sim.yaml,
# {plan.gap * 100:.1f} cm below the tool tip. Units: N, s, m, m/s.

follower:                 # Z follower, b = 30 N/(m/s)
  push_force: {num(g.follower_push_force)}         # [N] up along +Z
  push_duration: {num(g.follower_push_duration)}      # [s]

compliant_move:           # Z compliant move onto the obstacle, stopped by its 0.5 N force limit
  direction: {g.compliant_direction}           # down
  speed: {num(g.compliant_speed)}             # [m/s]
  max_travel: {num(g.compliant_max_travel)}        # [m] max path deviation

spring:                   # X spring, b = 30, k = 100
  direction: {g.spring_direction}            # push along +X
  push_force: {num(g.spring_push_force)}        # [N] for 3 s

hybrid:                   # X compliant move with a Z spring
  direction: {g.hybrid_direction}           # {direction}
  speed: {num(g.hybrid_speed)}             # [m/s]
  travel: {num(g.hybrid_travel)}             # [m] max path deviation, where the move ends
"""
    if not d.generic:
        force = contact_force_for(d.profile, g.contact_force_limit)
        text += f"""
contact_force:            # the compliant move's and the hybrid's force limit: the stop on contact
  limit: {num(g.contact_force_limit)}              # [N] the thesis's, with the simulated wrist sensor
  drivers:                # make demo DRIVER=<profile>: derived by make robot from the profile's wrench noise
    {d.profile}: {num(force.limit)}  # [N] {force.comment()}
"""
    return text
