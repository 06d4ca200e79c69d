"""The zero's drift, watched at rest (pure; see the README's *Zero drift*): a real sensor's zero moves with
temperature and after a hard press (a wrist sensor recorded moving ~9 N after a 98 N press). While no law and
no exceeded action runs and the wrench stays steady for `window` seconds, the mean of what the bias should be
minus the bias in use is the drift; `auto_tare_drift` > 0 re-tares there once it is larger."""

from __future__ import annotations

import math
from collections.abc import Sequence

from contact_control.zeroing import SteadyZero

__all__ = ["ZeroDrift"]


class ZeroDrift:
    """Windows of steady bias estimates at rest and the drift they show."""

    def __init__(self, window: float, max_force_spread: float, max_torque_spread: float,
                 spread_sigmas: float = 0.0) -> None:
        self.window = window
        self._spreads = (max_force_spread, max_torque_spread)
        self._sigmas = spread_sigmas
        #: The sensor's noise std per axis (the noise floor): steady means within `spread_sigmas` of it.
        self.noise: tuple[float, ...] | None = None
        self._steady = SteadyZero(window, max_force_spread, max_torque_spread)
        #: The last drift measured [N, Nm] per sensor axis (None before the first steady window).
        self.drift: tuple[float, ...] | None = None

    def restart(self) -> None:
        """Not at rest any more (a law or an exceeded action runs): the window starts again."""
        self._steady = SteadyZero(self.window, *self._spreads, spread_sigmas=self._sigmas, noise=self.noise)

    def add(self, estimate: Sequence[float], bias: Sequence[float], t: float) -> tuple[float, ...] | None:
        """One bias estimate at rest; the drift when a steady window completes (then a new one starts)."""
        mean = self._steady.add(estimate, t)
        if mean is None:
            return None
        self.drift = tuple(m - b for m, b in zip(mean, bias, strict=True))
        self.restart()
        return self.drift

    def rezeroed(self) -> None:
        """The bias was just set to the current reading (a tare): no drift, and a new window."""
        self.restart()
        self.drift = (0.0,) * 6

    @property
    def force(self) -> float:
        """|drift| of the force [N] (0 before it was measured)."""
        return 0.0 if self.drift is None else math.sqrt(sum(d * d for d in self.drift[:3]))
