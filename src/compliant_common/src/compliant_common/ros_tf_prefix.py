"""The tf prefix of the robot this node serves (compliant_common.tf_prefix; README, Namespaces)."""

from __future__ import annotations

import rospy

from compliant_common.tf_prefix import TfPrefix

__all__ = ["for_this_node"]


def for_this_node() -> TfPrefix:
    """The `tf_prefix` parameter nearest this node's namespace (rospy.search_param: a robot package's launch
    file sets it in the robot's namespace), or none."""
    key = rospy.search_param("tf_prefix")
    return TfPrefix(str(rospy.get_param(key, "")) if key else "")
