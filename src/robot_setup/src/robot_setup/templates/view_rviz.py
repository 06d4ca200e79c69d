"""config/view.rviz: RViz's saved view of the stack (compliant_rviz/launch/view.launch opens it): the robot
model and tf, the wrench on `wrench` (view.launch remaps it to the driver's topic) in the sensor's frame, and
compliant_rviz's markers (laws per axis, commanded velocity, obstacle, push, replay paths)."""

from __future__ import annotations

from collections.abc import Sequence

from robot_setup.plan import Plan

__all__ = ["view_rviz", "view_rviz_for"]


def view_rviz_for(plan: Plan) -> str:
    return view_rviz(plan.base, plan.obstacle_position, plan.reach)


def view_rviz(base: str, focus: Sequence[float], reach: float) -> str:
    """The config for an arm whose base frame is `base`, looking at `focus` [m] (the obstacle) from a distance
    that shows an arm of `reach` [m]."""
    fx, fy, fz = (float(v) for v in focus)
    distance = max(1.0, 2.2 * float(reach))
    return f"""Panels:
  - Class: rviz/Displays
    Name: Displays
    Property Tree Widget:
      Expanded: ~
      Splitter Ratio: 0.5
    Tree Height: 400
  - Class: rviz/Views
    Name: Views
    Splitter Ratio: 0.5
Visualization Manager:
  Class: ""
  Displays:
    - Class: rviz/Grid
      Name: Grid
      Enabled: true
      Alpha: 0.5
      Cell Size: 0.1
      Plane Cell Count: 20
      Color: 160; 160; 164
      Reference Frame: <Fixed Frame>
      Value: true
    - Class: rviz/RobotModel
      Name: RobotModel
      Enabled: true
      Robot Description: robot_description
      Visual Enabled: true
      Collision Enabled: false
      Alpha: 1
      Update Interval: 0
      Value: true
    - Class: rviz/TF
      Name: TF
      Enabled: true
      Show Names: false
      Show Axes: true
      Show Arrows: false
      Marker Scale: 0.15
      Update Interval: 0
      Frame Timeout: 15
      Value: true
    - Class: rviz/WrenchStamped
      Name: Wrench (sensor frame)
      Enabled: true
      Topic: wrench
      Queue Size: 10
      Unreliable: false
      Alpha: 1
      Arrow Width: 0.3
      Force Arrow Scale: 0.02
      Force Color: 204; 51; 51
      Torque Arrow Scale: 0.1
      Torque Color: 204; 204; 51
      History Length: 1
      Value: true
    - Class: rviz/MarkerArray
      Name: Stack (laws, velocity, obstacle, push, paths)
      Enabled: true
      Marker Topic: stack_markers/markers
      Queue Size: 10
      Namespaces: {{}}
      Value: true
  Enabled: true
  Global Options:
    Background Color: 48; 48; 48
    Default Light: true
    Fixed Frame: {base}
    Frame Rate: 15
  Name: root
  Tools:
    - Class: rviz/Interact
      Hide Inactive Objects: true
    - Class: rviz/MoveCamera
    - Class: rviz/Select
    - Class: rviz/FocusCamera
    - Class: rviz/Measure
  Value: true
  Views:
    Current:
      Class: rviz/Orbit
      Name: Current View
      Distance: {distance:.2f}
      Focal Point:
        X: {fx / 2:.3f}
        Y: {fy / 2:.3f}
        Z: {fz + 0.15:.3f}
      Near Clip Distance: 0.01
      Pitch: 0.45
      Yaw: 0.9
      Target Frame: <Fixed Frame>
      Value: Orbit (rviz)
    Saved: ~
Window Geometry:
  Displays:
    collapsed: false
  Views:
    collapsed: true
  Height: 720
  Width: 1000
  X: 0
  Y: 0
  Hide Left Dock: false
  Hide Right Dock: true
"""
