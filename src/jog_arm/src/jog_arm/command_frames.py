"""The frames a twist command may be expressed in: the model's frames and frames added with a fixed rotation.

Frames are resolved against the model once, on first use, so a cycle only reads what it needs: a frame fixed
to the root has its rotation stored (commands in it are rotated once, when they arrive); any other frame is
rotated every cycle, at the cycle's configuration.
"""

from __future__ import annotations

import numpy as np
from compliant_common.typedefs import FloatArray

from jog_arm.kinematics import ArmModel, KinematicsError

__all__ = ["CommandFrame", "CommandFrames"]


class CommandFrame:
    """A command frame resolved against the model: a model frame, possibly with a fixed extra rotation."""

    __slots__ = ("extra", "frame_id", "on_chain", "static", "static_rows")

    def __init__(
        self, frame_id: int, static: FloatArray | None, on_chain: bool, extra: FloatArray | None
    ) -> None:
        self.frame_id = frame_id
        self.static = static  # root <- frame rotation if it never moves, else None
        # The same as float rows: rotating one twist by hand beats numpy's per-call overhead.
        self.static_rows = None if static is None else tuple(map(tuple, static.tolist()))
        self.on_chain = on_chain  # refreshed by the cycle's Jacobian (no forward kinematics needed)
        self.extra = extra  # model frame <- command frame rotation, or None


class CommandFrames:
    """Registry of command frames by name (without a leading "/").

    Args:
        model: The arm model whose frames are known without being added.
    """

    def __init__(self, model: ArmModel) -> None:
        self._model = model
        self._frames: dict[str, CommandFrame] = {}

    def resolve(self, name: str) -> CommandFrame | None:
        """The frame `name` (a model frame or an added one), None if unknown."""
        frame = self._frames.get(name)
        if frame is None and self._model.has_frame(name):
            model = self._model
            fid = model.frame_id(name)
            parent_joint = model.model.frames[fid].parentJoint
            static = model.model.frames[fid].placement.rotation.copy() if parent_joint == 0 else None
            frame = CommandFrame(fid, static, model.moves_with_tip_chain(fid), None)
            self._frames[name] = frame
        return frame

    def add(self, name: str, parent: str, rotation: FloatArray) -> None:
        """Makes a frame the model does not know usable for commands, fixed relative to a model frame.

        Args:
            name: New frame name.
            parent: A frame of the model (or one added before).
            rotation: 3x3 rotation taking vectors in `name` to `parent` (the rotation of `name` in `parent`).

        Raises:
            KinematicsError: `parent` is unknown.
            ValueError: `rotation` is not a rotation matrix.
        """
        base = self.resolve(parent.lstrip("/"))
        if base is None:
            raise KinematicsError(f"{parent!r} is not a frame of the robot model")
        rot = np.array(rotation, dtype=float)
        if rot.shape != (3, 3) or not np.allclose(rot @ rot.T, np.eye(3), atol=1e-6):
            raise ValueError(f"rotation of frame {name!r} must be a 3x3 rotation matrix")
        extra = rot if base.extra is None else base.extra @ rot
        static = None if base.static is None else base.static @ rot
        self._frames[name.lstrip("/")] = CommandFrame(base.frame_id, static, base.on_chain, extra)

    def rotation(self, frame: CommandFrame, q: FloatArray) -> FloatArray:
        """Root <- `frame` rotation at configuration `q` (model order), for a frame that moves.

        A frame on the tip's chain is read from the placements the cycle's Jacobian left in the model's
        data; any other one needs forward kinematics at `q`.
        """
        rot = self._model.frame_rotation(frame.frame_id, None if frame.on_chain else q)
        if frame.extra is not None:
            rot = rot @ frame.extra
        return rot
