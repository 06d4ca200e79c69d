"""What a fit finds: rest windows, one fit per axis, gaps, jumps, the offset change across a contact, and
:class:`SensorFit` holding them all (made by :func:`sensor_fit.noise_model.fit_recording`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["GAP_FACTOR", "AxisFit", "ContactShift", "Gap", "Jump", "RestWindow", "SensorFit"]

GAP_FACTOR = 3.0            # an interval longer than this many median intervals is a gap


@dataclass(frozen=True)
class RestWindow:
    """A stretch at rest: [t0, t1] [s], its sample count and per-axis mean (offset)."""

    t0: float
    t1: float
    n: int
    mean: tuple[float, ...]
    given: bool = False


@dataclass(frozen=True)
class AxisFit:
    """One axis fitted on the rest window.

    Attributes:
        axis, unit: ``fx`` .. ``tz``; N or Nm.
        offset: The window's mean.
        std: The window's sample standard deviation.
        white: White-noise std.
        drift: AR(1) drift's stationary std (a lower bound when tau is undetermined for a short window).
        tau: Drift time constant [s]; None when undetermined (``note`` says why).
        lag1: Lag-1 autocorrelation of the window.
        note: Why tau is undetermined ("" otherwise).
    """

    axis: str
    unit: str
    offset: float
    std: float
    white: float
    drift: float
    tau: float | None
    lag1: float
    note: str = ""

    @property
    def fitted_std(self) -> float:
        """The model's total std: sqrt(white^2 + drift^2)."""
        return math.hypot(self.white, self.drift)


@dataclass(frozen=True)
class Gap:
    """An interval over :data:`GAP_FACTOR` median intervals: starting at ``time`` [s], ``length`` [s]."""

    time: float
    length: float


@dataclass(frozen=True)
class Jump:
    """An axis's largest one-sample change over the recording: ``value`` at ``time`` (the later sample)."""

    axis: str
    unit: str
    value: float
    time: float
    after_gap: bool


@dataclass(frozen=True)
class ContactShift:
    """How the rest offset moved from the first to the last rest window, across the press in between.

    Attributes:
        first, last: The two rest windows.
        change: last.mean - first.mean, 6 axes.
        peak: Largest |F - first offset| between them [N] (the press a tared sensor would read).
        peak_force: That press's force vector (relative to the first offset) [N].
        peak_time: Its time [s].
    """

    first: RestWindow
    last: RestWindow
    change: tuple[float, ...]
    peak: float
    peak_force: tuple[float, float, float]
    peak_time: float

    @property
    def force_change(self) -> float:
        """|offset change| of the force [N]."""
        return float(np.linalg.norm(self.change[:3]))

    @property
    def fraction(self) -> float:
        """|force offset change| / peak press magnitude."""
        return self.force_change / self.peak if self.peak > 0 else 0.0


@dataclass
class SensorFit:
    """Everything :func:`~sensor_fit.noise_model.fit_recording` found (the methods: its module docstring)."""

    source: str
    n: int
    duration: float
    dt_median: float
    dt_std: float
    dt_min: float
    dt_max: float
    gaps: list[Gap]
    rest_windows: list[RestWindow]
    fit_window: RestWindow
    axes: list[AxisFit]
    jumps: list[Jump]
    shift: ContactShift | None
    contact: bool
    common_tau: float | None
    common: list[tuple[float, ...]]   # per axis (white, drift) refitted with common_tau
    min_rest: float = 0.3
    method: str = "whittle"
    notes: list[str] = field(default_factory=list)

    @property
    def rate(self) -> float:
        """Sample rate [Hz] from the median interval."""
        return 1.0 / self.dt_median
