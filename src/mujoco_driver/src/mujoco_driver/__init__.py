"""MuJoCo simulation of a position-controlled arm with a wrist force/torque sensor.

Submodules (imported explicitly, so that ``description`` stays usable without numpy or mujoco):
``description`` (URDF + sensor + tool), ``config`` (scene settings), ``scene`` (MjModel builder),
``sim`` (the stepping core).
"""
