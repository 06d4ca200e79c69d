"""CMakeLists.txt: a catkin package that installs config/ and launch/ (no code)."""

from __future__ import annotations

from robot_setup.plan import Plan

__all__ = ["cmakelists_txt"]


def cmakelists_txt(plan: Plan) -> str:
    return f"""cmake_minimum_required(VERSION 3.0.2)
project({plan.spec.name}_custom)

find_package(catkin REQUIRED)
catkin_package()

install(DIRECTORY config launch DESTINATION ${{CATKIN_PACKAGE_SHARE_DESTINATION}})
"""
