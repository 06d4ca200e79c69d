"""What the sensor can resolve, measured while zeroing (pure; see the README's *Knowing the sensor*).

The start-up zeroing window holds the sensor at rest: the spread of its samples there is the noise floor.
What the laws see is that noise after the low-pass filter. For white noise a second-order Butterworth
filter with cutoff fc at sample rate fs passes a fraction 2 * 1.1107 * fc / fs of its variance (1.1107 fc
is that filter's equivalent noise bandwidth, B). Real sensors' noise is mostly slow, not white (a
joint-torque estimate and a built-in wrist sensor recorded at rest: lag-1 autocorrelations 0.6-0.97, fitted
with sensor_fit's fit_sensor; the package README): taken as first-order noise with the measured lag-1
correlation a (correlation time tau = -T / ln a), a fraction (2 / pi) atan(2 pi tau B) of its variance
passes. The larger of the two is used.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["BUTTERWORTH2_ENBW", "NoiseFloor", "filtered_fraction"]

BUTTERWORTH2_ENBW = (math.pi / 4.0) / math.sin(math.pi / 4.0)  # 1.1107: noise bandwidth / cutoff, 2nd order


def filtered_fraction(rate: float, cutoff: float | None, lag1: float = 0.0) -> float:
    """The factor on a noise's std after the low-pass filter (1 without one, or at a low rate), for noise
    with lag-1 autocorrelation `lag1` at `rate` (0: white)."""
    if cutoff is None or not rate > 0.0:
        return 1.0
    band = BUTTERWORTH2_ENBW * cutoff
    white = min(1.0, 2.0 * band / rate)
    if lag1 <= 0.0:
        return math.sqrt(white)
    tau = -1.0 / (rate * math.log(min(lag1, 0.9999)))
    return math.sqrt(max(white, (2.0 / math.pi) * math.atan(2.0 * math.pi * tau * band)))


@dataclass(frozen=True)
class NoiseFloor:
    """The sensor's noise at rest.

    Attributes:
        std: Standard deviation per sensor axis over the zeroing window [N, Nm] (fx, fy, fz, tx, ty, tz).
        rate: The sample rate it was measured at [Hz].
        samples: How many samples.
        filtered: The same after the low-pass filter (white-noise estimate) [N, Nm].
    """

    std: tuple[float, ...]
    rate: float
    samples: int
    filtered: tuple[float, ...]

    @classmethod
    def measure(cls, std: Sequence[float], rate: float, samples: int, cutoff: float | None,
                lag1: Sequence[float] = (0.0,) * 6) -> NoiseFloor:
        """From the stds and lag-1 autocorrelations of a window at rest, with the filter's cutoff [Hz]. A
        correlation within two standard errors of zero (2 / sqrt(samples)) is taken as white noise."""
        significant = 2.0 / math.sqrt(max(samples, 1))
        return cls(tuple(std), rate, samples,
                   tuple(filtered_fraction(rate, cutoff, a if a > significant else 0.0) * s
                         for s, a in zip(std, lag1, strict=True)))

    @property
    def force(self) -> float:
        """The largest filtered force std [N] (axes rotate between frames: the worst one bounds them)."""
        return max(self.filtered[:3])

    @property
    def torque(self) -> float:
        """The largest filtered torque std [Nm]."""
        return max(self.filtered[3:])

    def resolvable(self, sigmas: float) -> tuple[float, float]:
        """The smallest force and torque limits the sensor tells from its noise: `sigmas` filtered stds."""
        return sigmas * self.force, sigmas * self.torque

    def describe(self) -> str:
        raw = ", ".join(f"{s:.3g}" for s in self.std)
        filt = ", ".join(f"{s:.3g}" for s in self.filtered)
        return (f"noise floor at rest over {self.samples} samples at {self.rate:.4g} Hz: std [{raw}] "
                f"(N, Nm, sensor frame), after the low-pass filter [{filt}]")
