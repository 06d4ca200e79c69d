"""How much loop gain the sensor's rate and the command path's latency keep stable (pure; see the README's
*Loop gain and the sensor's rate*).

A law closes a loop through the arm: the spring's V = scale * (F / b - k d) is a position loop of gain
scale * k [1/s]; force tracking's V = (F - F_target) / b against a surface of stiffness K_s is a force loop of
gain K_s / b. Each has a delay: the sample period T of what it measures, the low-pass filter's group delay
(sqrt(2) / (2 pi fc) for the second-order Butterworth, on the force path only) and the command path's latency
(`command_latency`: the jogger's period, the driver, the arm's servo). An integrator loop K / s with delay tau
keeps a phase margin of pi / 2 - K tau, so K tau <= `loop_gain_delay` (0.5: 61 degrees) bounds the gain. At a
30 Hz wrench and a 20 Hz jogger the thesis's spring (0.2 x 100 = 20 1/s) has K tau ~ 2: it oscillates.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from contact_control.axes import AXES, LAW_FORCE_TRACKING, LAW_SPRING
from contact_control.laws import AxisLaw

__all__ = ["GainBound", "filter_delay"]


def filter_delay(cutoff: float | None) -> float:
    """Group delay at low frequency of the second-order Butterworth low-pass [s] (0 without one)."""
    return 0.0 if not cutoff else math.sqrt(2.0) / (2.0 * math.pi * cutoff)


class GainBound:
    """The largest loop gain per law for a sensor period, a filter and a command latency.

    Args:
        product: The largest gain x delay (0: no bound).
        latency: The command path's latency [s].
        spring_scale: The spring's output scale (its gain is scale * k).
        contact_stiffness: The surface's stiffness for force tracking [N/m] (0: unknown, not bounded).
    """

    def __init__(self, product: float, latency: float, spring_scale: float, contact_stiffness: float) -> None:
        self.product, self.latency = product, latency
        self.spring_scale, self.contact_stiffness = spring_scale, contact_stiffness

    def delays(self, period: float, cutoff: float | None) -> tuple[float, float]:
        """The delay of a position loop (spring) and of a force loop (force tracking) [s]."""
        position = period + self.latency
        return position, position + filter_delay(cutoff)

    def limit(
        self, laws: Sequence[AxisLaw], period: float, cutoff: float | None
    ) -> tuple[list[AxisLaw], list[str]]:
        """The laws with gains over the bound lowered to it, and a note per lowered axis."""
        out: list[AxisLaw] = list(laws)
        notes: list[str] = []
        if self.product <= 0.0:
            return out, notes
        position, force = self.delays(period, cutoff)
        for i, law in enumerate(laws):
            if law.law == LAW_SPRING and law.stiffness * self.spring_scale * position > self.product:
                k = self.product / (self.spring_scale * position)
                out[i] = replace(law, stiffness=k)
                notes.append(f"{AXES[i]} spring k {law.stiffness:g} -> {k:.3g} 1/s")
            stiffness = 0.0 if i >= 3 else self.contact_stiffness  # linear axes: N/m
            if law.law == LAW_FORCE_TRACKING and stiffness * force > self.product * law.damping > 0.0:
                b = stiffness * force / self.product
                out[i] = replace(law, damping=b)
                notes.append(f"{AXES[i]} force tracking b {law.damping:g} -> {b:.3g}")
        if notes:
            notes.append(f"(loop gain x delay <= {self.product:g}: the wrench every {period * 1e3:.3g} ms, "
                         f"command latency {self.latency * 1e3:.3g} ms; loop_gain_delay, command_latency)")
        return out, notes
