"""Second-order Butterworth low-pass filter, the one netft_utils applied to the wrench, with unit DC gain.

Parameters as netft_utils used them: `delta_t` is the sample period [s] the filter is designed for and
`cutoff_freq` its cutoff [Hz]; the pre-warped bilinear transform uses Omega = tan(pi * cutoff * delta_t).
The filter takes one step per received sample and never looks at clocks, so on a sensor that really publishes
every T seconds the cutoff is `cutoff_freq * delta_t / T` Hz: the design fixes the cutoff as a fraction
`cutoff_freq * delta_t` of the sample rate (0.12 for the defaults 0.2 s, 0.6 Hz; 0.33 for the thesis's
real-robot override 0.62 s, 0.53 Hz). That product must stay below 0.5 (Nyquist).

The original had `sqrt(2 * Omega + 1)` where the Butterworth denominator needs `sqrt(2) * Omega + 1`, so a
steady force came out scaled by 1.129 (real-robot override 0.62 s, 0.53 Hz) or 1.546 (defaults);
`legacy_typo=True` reproduces it for comparison only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["LowPass", "butterworth_coefficients", "dc_gain"]

Coefficients = tuple[float, float, float, float, float]


def butterworth_coefficients(delta_t: float, cutoff_freq: float, legacy_typo: bool = False) -> Coefficients:
    """Coefficients (a0, a1, a2, b1, b2) of y = a0 x + a1 x1 + a2 x2 - b1 y1 - b2 y2.

    Args:
        delta_t: design sample period [s], > 0.
        cutoff_freq: cutoff [Hz], > 0, below 0.5 / delta_t.
        legacy_typo: use the original's wrong denominator (DC gain != 1).

    Raises:
        ValueError: arguments out of range.
    """
    if not (delta_t > 0.0 and cutoff_freq > 0.0 and cutoff_freq * delta_t < 0.5):
        raise ValueError(f"need delta_t > 0 and 0 < cutoff_freq < 0.5/delta_t, got {delta_t}, {cutoff_freq}")
    omega = math.tan(math.pi * cutoff_freq * delta_t)
    w2 = omega * omega
    den = w2 + (math.sqrt(2.0 * omega + 1.0) if legacy_typo else math.sqrt(2.0) * omega + 1.0)
    a0 = w2 / den
    return (a0, 2.0 * a0, a0, 2.0 * (w2 - 1.0) / den, (w2 - math.sqrt(2.0) * omega + 1.0) / den)


def dc_gain(coefficients: Coefficients) -> float:
    """Output/input ratio for a constant input."""
    a0, a1, a2, b1, b2 = coefficients
    return (a0 + a1 + a2) / (1.0 + b1 + b2)


class LowPass:
    """The filter on N channels (a wrench: 6), plain floats for speed on small vectors."""

    def __init__(
        self, delta_t: float, cutoff_freq: float, channels: int = 6, legacy_typo: bool = False
    ) -> None:
        self.coefficients = butterworth_coefficients(delta_t, cutoff_freq, legacy_typo)
        self._n = channels
        self._x1 = [0.0] * channels
        self._x2 = [0.0] * channels
        self._y1 = [0.0] * channels
        self._y2 = [0.0] * channels
        self._primed = False

    @property
    def last(self) -> list[float] | None:
        """The last outputs (a copy), None before the first sample."""
        return list(self._y1) if self._primed else None

    def reset(self, values: Sequence[float] | None = None) -> None:
        """Forgets the history; the next step starts in steady state at its input (or at `values`)."""
        if values is None:
            self._primed = False
            return
        for state in (self._x1, self._x2, self._y1, self._y2):
            state[:] = values
        self._primed = True

    def step(self, x: Sequence[float]) -> list[float]:
        """Filters one sample of every channel and returns the outputs (a new list)."""
        if not self._primed:
            # Starting from rest at zero would show a transient from 0 to the first sample.
            self.reset(x)
        a0, a1, a2, b1, b2 = self.coefficients
        x1, x2, y1, y2 = self._x1, self._x2, self._y1, self._y2
        out = [0.0] * self._n
        for i in range(self._n):
            xi = x[i]
            yi = a0 * xi + a1 * x1[i] + a2 * x2[i] - b1 * y1[i] - b2 * y2[i]
            x2[i] = x1[i]
            x1[i] = xi
            y2[i] = y1[i]
            y1[i] = yi
            out[i] = yi
        return out
