"""ISO/TS 15066 power and force limiting: the body regions of its Annex A and the speed a robot may have
toward one (the package README, *Collaborative speed cap*). No ROS here.

A transient contact between a robot of effective mass m_R and a body region of effective mass m_H and
stiffness k may reach the force F_T when the energy they exchange, (1/2) mu v^2 with the reduced mass
mu = (1/m_H + 1/m_R)^-1, is what the region's spring stores at F_T, F_T^2 / (2 k); hence
v_max = F_T / sqrt(mu k) (ISO/TS 15066:2016, A.5). F_T is twice the quasi-static limit (Table A.2, note c),
except for the head and the neck, where the standard permits no transient contact: there the quasi-static
limit is used (a choice: the most cautious reading).
"""

from __future__ import annotations

import math
from typing import NamedTuple

__all__ = ["OFF", "REGIONS", "BodyRegion", "max_speed", "region_named"]

OFF = "off"  # the region name that turns the cap off


class BodyRegion(NamedTuple):
    """One row of ISO/TS 15066 Annex A."""

    name: str
    force: float  # maximum permissible quasi-static force [N] (Table A.2)
    stiffness: float  # effective spring constant k [N/m] (Table A.3; the table gives N/mm)
    mass: float  # effective mass m_H [kg] (Table A.3)
    transient: float  # F_T / F: 2 where a transient contact is permitted, 1 where it is not

    @property
    def transient_force(self) -> float:
        """F_T [N], the force a transient contact may reach."""
        return self.force * self.transient


# ISO/TS 15066:2016 Annex A, Tables A.2 and A.3 (the values also in Behrens et al. 2022, Front. Robot. AI 8,
# 667818, which reports the study behind them).
REGIONS: dict[str, BodyRegion] = {r.name: r for r in (
    BodyRegion("skull", 130.0, 150e3, 4.4, 1.0),
    BodyRegion("face", 65.0, 75e3, 4.4, 1.0),
    BodyRegion("neck", 150.0, 50e3, 1.2, 1.0),
    BodyRegion("back", 210.0, 35e3, 40.0, 2.0),
    BodyRegion("chest", 140.0, 25e3, 40.0, 2.0),
    BodyRegion("abdomen", 110.0, 10e3, 40.0, 2.0),
    BodyRegion("pelvis", 180.0, 25e3, 40.0, 2.0),
    BodyRegion("upper_arm", 150.0, 30e3, 3.0, 2.0),
    BodyRegion("lower_arm", 160.0, 40e3, 2.0, 2.0),
    BodyRegion("hand", 140.0, 75e3, 0.6, 2.0),
    BodyRegion("thigh", 220.0, 50e3, 75.0, 2.0),
    BodyRegion("lower_leg", 130.0, 60e3, 75.0, 2.0),
)}


def region_named(name: str) -> BodyRegion:
    """The region called `name`; ValueError naming the known ones otherwise."""
    try:
        return REGIONS[name]
    except KeyError:
        raise ValueError(f"unknown body region {name!r}: one of {', '.join(REGIONS)}") from None


def max_speed(region: BodyRegion, robot_mass: float) -> float:
    """v_max [m/s] toward `region` for a robot of effective mass `robot_mass` [kg] in that direction."""
    if not robot_mass > 0.0:
        return math.inf  # nothing moves that way: no energy to transfer
    mu = 1.0 / (1.0 / region.mass + 1.0 / robot_mass)
    return region.transient_force / math.sqrt(mu * region.stiffness)
