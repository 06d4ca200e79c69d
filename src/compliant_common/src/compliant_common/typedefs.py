"""Type aliases shared by the stack's packages (no `Any` in their public signatures)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

__all__ = ["FloatArray", "ParamMap"]

#: A numpy array of float64 (joint vectors, Jacobians, rotations).
FloatArray: TypeAlias = npt.NDArray[np.float64]

#: Parameters by key, as `rospy.get_param` returns them (nested dicts, lists, scalars) or as checked by a
#: `compliant_common.schema.Schema`: each value is checked where it is read, so values are `object`.
ParamMap: TypeAlias = Mapping[str, object]
