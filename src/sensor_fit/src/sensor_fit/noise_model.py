"""The noise model of a wrench recording: white noise and an AR(1) drift per axis, fitted on a rest window.

Per axis on the rest window (:mod:`sensor_fit.rest_windows`): the offset (mean), white noise and a slow
drift modelled as an AR(1) process (stationary std and time constant); over the recording: the sample rate
and its jitter, gaps, the largest one-sample jumps, and the offset change across a contact (first vs last
rest window). :func:`fit_recording` returns them all as a :class:`~sensor_fit.results.SensorFit`.

Model of one axis at rest: ``x_k = offset + w_k + d_k`` with ``w`` white (std sigma_w) and
``d_k = a d_{k-1} + e_k``, ``a = exp(-dt/tau)`` (stationary std sigma_d). Its autocovariance is
``sigma_w^2 + sigma_d^2`` at lag 0 and ``sigma_d^2 a^k`` at lag k >= 1; its spectral density (the Fourier
transform of that) is ``sigma_w^2 + sigma_d^2 (1 - a^2) / (1 - 2 a cos(omega) + a^2)``. Two fits of it:

* ``whittle`` (default): the spectrum fitted to the rest window's periodogram by maximum likelihood
  (Whittle's approximation: minimise sum(log S + I / S) over the Fourier frequencies; for each tau of a
  log-spaced grid, refined around its best, sigma_w^2 and sigma_d^2 by scoring iterations). It leaves out
  frequency 0, so removing the window's mean does not bias it.
* ``acf``: the sample autocovariance (mean removed) at lags 1..K (K: twice the first lag where it falls
  below 2 var / sqrt(n)) fitted in least squares for each tau of the same grid, with lag 0 matched exactly
  (sigma_w^2 = var - sigma_d^2, clamped >= 0); the expected values include the bias of the mean's removal.
  On generated data (white 0.3 + drift 0.2, tau = 6 to 25 samples, windows of 200 to 1000 tau; 40 seeds
  each) its tau errors are heavier-tailed: rms 12-34 %, worst 2.2x, against Whittle's rms 8-19 %, worst
  43 %; its stds are also a little worse. Hence Whittle is the default.

tau is *undetermined* (None) when no positive lag-1 correlation is seen (lag-1 autocorrelation <=
3 / sqrt(n)) or, with Whittle, when white noise alone fits about as well (-log L within 3: a likelihood-ratio
test at 95 % for 2 parameters): then all the variance is white; when it comes out below half a sample
interval (drift indistinguishable from white); or when it comes out above a tenth of the window or, with
Whittle, some tau above a tenth of the window fits about as well (-log L within 2, 95 % for 1 parameter):
the window is too short to see the drift decorrelate, and the drift std printed is then the lag-1
autocovariance's square root, what the window shows, a lower bound. A window of T seconds gives a rough tau
unless T is some hundreds of tau: on generated data the rms error is 8 % at T = 1000 tau and 15-19 % at
200-400 tau; at T = 16 tau most fits say undetermined, and the few that do not underestimate tau by half.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sensor_fit.errors import SensorFitError
from sensor_fit.recordings import AXES, MIN_SAMPLES, UNITS
from sensor_fit.rest_windows import REST_RULE, find_rest_windows, given_window
from sensor_fit.results import GAP_FACTOR, AxisFit, ContactShift, Gap, Jump, RestWindow, SensorFit

__all__ = ["CONTACT_FACTOR", "METHODS", "fit_axis", "fit_recording"]

METHODS = ("whittle", "acf")
TAU_MAX_FRACTION = 0.1      # tau is determined only up to this fraction of the fit window
LIKELIHOOD_WHITE = 3.0      # Whittle: the drift must lower -log L by this (chi2, 2 dof, 95 %: 6/2) ...
LIKELIHOOD_TAU = 2.0        # ... and every tau over a tenth of the window must fit worse by this (1 dof)
CONTACT_FACTOR = 10.0       # a press counts as a contact above this many times the largest force std


def _autocov(x: np.ndarray, k_max: int) -> np.ndarray:
    """Sample autocovariance (mean removed, divisor n) at lags 0..k_max."""
    n = len(x)
    xc = x - x.mean()
    size = 1 << math.ceil(math.log2(2 * n))
    f = np.fft.rfft(xc, size)
    return np.fft.irfft(f * np.conj(f), size)[: k_max + 1] / n


def _white_expectation(n: int, k_max: int) -> np.ndarray:
    """E[sample autocovariance] of unit white noise, mean removed: (n-1)/n at 0, -(n-k)/n^2 after."""
    k = np.arange(k_max + 1)
    g = -(n - k) / n**2
    g[0] = (n - 1) / n
    return g


def _ar1_expectation(a: float, n: int, k_max: int) -> np.ndarray:
    """E[sample autocovariance] at lags 0..k_max of a unit-variance AR(1) (autocovariance a^k) with the
    sample mean removed (divisor n): ((n-k) a^k - sum_i (r_i + r_{i+k}) + (n-k) V) / n, with
    r_i = Cov(x_i, mean) and V = Var(mean)."""
    i = np.arange(n)
    r = ((1.0 - a ** (i + 1)) + (a - a ** (n - i))) / ((1.0 - a) * n)
    v = r.mean()
    p = np.concatenate([[0.0], np.cumsum(r)])
    k = np.arange(k_max + 1)
    s = p[n - k] + (p[n] - p[k])
    return ((n - k) * a**k - s + (n - k) * v) / n


def _acf_fixed(c: np.ndarray, n: int, a: float, k_max: int) -> tuple[float, float, float]:
    """Autocovariance fit for a given a: (sigma_w^2, sigma_d^2, residual), lags 1..k_max in least squares
    with lag 0 matched exactly (expected values with the window's mean removed)."""
    gw = _white_expectation(n, k_max)
    gd = _ar1_expectation(a, n, k_max)
    y = c[1 : k_max + 1] - c[0] * gw[1:] / gw[0]
    h = gd[1:] - gd[0] * gw[1:] / gw[0]
    hh = float(h @ h)
    s2d = float(y @ h) / hh if hh > 0 else 0.0
    s2d = min(max(s2d, 0.0), c[0] / gd[0])
    s2w = max((c[0] - s2d * gd[0]) / gw[0], 0.0)
    return s2w, s2d, float(np.sum((y - s2d * h) ** 2))


def _acf_lags(n: int, c: np.ndarray) -> int:
    """Lags used by the autocovariance fit: twice the first lag whose autocovariance falls below its noise
    (2 c0 / sqrt(n)), at least 10, at most n/4."""
    below = np.flatnonzero(c[1:] < 2.0 * c[0] / math.sqrt(n))
    first = int(below[0]) + 1 if len(below) else len(c) - 1
    return int(min(len(c) - 1, max(10, 2 * first)))


def _periodogram(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Periodogram |DFT|^2 / n (mean removed) at the Fourier frequencies strictly between 0 and Nyquist,
    and cos(omega) there; its expectation is the spectral density S, whose mean over frequency is the
    variance."""
    n = len(x)
    m = (n - 1) // 2
    spec = np.abs(np.fft.rfft(x - x.mean())) ** 2 / n
    return spec[1 : m + 1], np.cos(2.0 * np.pi * np.arange(1, m + 1) / n)


def _ar1_spectrum(a: float, cosw: np.ndarray) -> np.ndarray:
    """Spectral density of a unit-variance AR(1): (1 - a^2) / (1 - 2 a cos(omega) + a^2)."""
    return (1.0 - a * a) / (1.0 - 2.0 * a * cosw + a * a)


def _whittle_fixed(spec: np.ndarray, g: np.ndarray) -> tuple[float, float, float]:
    """Whittle fit of S = sigma_w^2 + sigma_d^2 g for a given AR(1) shape g: (sigma_w^2, sigma_d^2, -log
    likelihood). With S = s h, h = q + (1 - q) g, the best scale s is mean(I / h) in closed form; q (the
    white share) is bracketed on a logistic grid, then found by safeguarded Newton steps on d(-log L)/dq, and
    compared with the boundaries (white only, drift only)."""
    m = len(spec)
    omg = 1.0 - g

    def nll(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        h = q[:, None] + (1.0 - q[:, None]) * g[None, :]
        scale = np.mean(spec[None, :] / h, axis=1)
        return m * np.log(scale) + np.sum(np.log(h), axis=1) + m, scale

    def slope(q: float) -> tuple[float, float]:
        h = g + q * omg
        r = spec / h
        a = float(r.mean())
        b = float(np.mean(r * omg / h)) / a
        c = float(np.mean(r * (omg / h) ** 2)) / a
        k = omg / h
        return -m * b + float(k.sum()), m * (2.0 * c - b * b) - float(np.sum(k * k))

    u = np.linspace(-24.0, 24.0, 13)
    grid = 1.0 / (1.0 + np.exp(-u))
    values = np.concatenate([nll(grid[k : k + 4])[0] for k in range(0, len(grid), 4)])
    i = int(np.argmin(values))
    lo, hi = float(grid[max(i - 1, 0)]), float(grid[min(i + 1, len(grid) - 1)])
    q = float(grid[i])
    for _ in range(60):
        d1, d2 = slope(q)
        if d1 > 0.0:
            hi = q
        else:
            lo = q
        step = q - d1 / d2 if d2 > 0.0 else math.nan
        new = step if lo < step < hi else 0.5 * (lo + hi)
        if abs(new - q) <= 1e-14 + 1e-10 * q or hi - lo <= 1e-15:
            q = new
            break
        q = new
    value, scale = nll(np.array([q]))
    s_w = float(spec.mean())
    s_d = float(np.mean(spec / g))
    options = [(float(value[0]), float(scale[0]) * q, float(scale[0]) * (1.0 - q)),
               (m * math.log(s_w) + m, s_w, 0.0),
               (m * math.log(s_d) + float(np.sum(np.log(g))) + m, 0.0, s_d)]
    best, s2w, s2d = min(options)
    return s2w, s2d, best


def _search(cost, lo: float, hi: float) -> tuple[float, float]:
    """The tau in [lo, hi] with the smallest cost, and that cost: a log-spaced grid, then a finer one around
    its best."""
    grid = np.geomspace(lo, hi, 80)
    values = [cost(float(tau)) for tau in grid]
    i = int(np.argmin(values))
    fine = np.geomspace(grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)], 21)
    values_fine = [cost(float(tau)) for tau in fine]
    j = int(np.argmin(values_fine))
    return float(fine[j]), float(values_fine[j])


def _fit_fixed(x: np.ndarray, dt: float, tau: float, method: str) -> tuple[float, float]:
    """(sigma_w^2, sigma_d^2) of one axis with the drift's time constant fixed."""
    a = math.exp(-dt / tau)
    if method == "acf":
        n = len(x)
        c = _autocov(x, max(2, min(n // 4, 4000)))
        return _acf_fixed(c, n, a, _acf_lags(n, c))[:2]
    spec, cosw = _periodogram(x)
    return _whittle_fixed(spec, _ar1_spectrum(a, cosw))[:2]


def fit_axis(x: np.ndarray, dt: float, axis: str = "fx", unit: str = "N", method: str = "whittle") -> AxisFit:
    """White noise + AR(1) drift of one axis's rest samples ``x`` at interval ``dt`` (module docstring).

    Args:
        method: ``whittle`` (the model's spectrum fitted to the periodogram by maximum likelihood) or ``acf``
            (its autocovariance fitted to the sample autocovariance in least squares).
    """
    if method not in METHODS:
        raise SensorFitError(f"fit method {method!r}: one of {list(METHODS)}")
    x = np.asarray(x, dtype=float)
    n = len(x)
    if n < MIN_SAMPLES:
        raise SensorFitError(f"fit window: too few samples ({n} < {MIN_SAMPLES})")
    c = _autocov(x, max(2, min(n // 4, 4000)))
    std = float(np.sqrt(c[0] * n / (n - 1)))
    lag1 = float(c[1] / c[0]) if c[0] > 0 else 0.0
    span = n * dt
    common: dict[str, Any] = {"axis": axis, "unit": unit, "offset": float(x.mean()), "std": std, "lag1": lag1}
    if c[0] <= 0 or lag1 <= 3.0 / math.sqrt(n):
        return AxisFit(white=std, drift=0.0, tau=None, note=f"no drift seen (lag-1 correlation {lag1:.2f} "
                       f"<= 3/sqrt(n) = {3.0 / math.sqrt(n):.2f})", **common)
    if method == "acf":
        k_max = _acf_lags(n, c)

        def cost(tau: float) -> float:
            return _acf_fixed(c, n, math.exp(-dt / tau), k_max)[2]
    else:
        spec, cosw = _periodogram(x)

        def cost(tau: float) -> float:
            return _whittle_fixed(spec, _ar1_spectrum(math.exp(-dt / tau), cosw))[2]

    long_tau = TAU_MAX_FRACTION * span
    tau, best = _search(cost, 0.3 * dt, 0.5 * span)
    s2w, s2d = _fit_fixed(x, dt, tau, method)
    if method == "whittle" and s2d > 0.0:
        m = len(spec)
        gain = m * math.log(float(spec.mean())) + m - best        # -log L of white noise alone - the best
        if gain < LIKELIHOOD_WHITE:
            return AxisFit(white=std, drift=0.0, tau=None, note=f"no drift seen (the drift improves -log L "
                           f"by {gain:.2g} < {LIKELIHOOD_WHITE:g})", **common)
        if tau <= long_tau:
            margin = min(cost(float(v)) for v in np.geomspace(long_tau, 0.5 * span, 15)) - best
            if margin < LIKELIHOOD_TAU:
                tau = math.inf   # a tau beyond a tenth of the window fits about as well
    if s2d <= 0.0:
        return AxisFit(white=std, drift=0.0, tau=None, note="no drift fitted", **common)
    if tau < 0.5 * dt:
        return AxisFit(white=std, drift=0.0, tau=None,
                       note=f"drift faster than half a sample ({tau * 1e3:.2g} ms): counted as white",
                       **common)
    if tau > long_tau:
        s2d_seen = min(max(float(c[1]), 0.0), float(c[0]))
        return AxisFit(white=math.sqrt(c[0] - s2d_seen), drift=math.sqrt(s2d_seen), tau=None,
                       note=f"tau > {long_tau:.3g} s fits {'best' if tau < math.inf else 'about as well'}: "
                            "window too short to see the drift (drift std: the lag-1 autocovariance's root, "
                            "what the window shows: a lower bound)", **common)
    return AxisFit(white=math.sqrt(s2w), drift=math.sqrt(s2d), tau=tau, **common)

def fit_recording(t: np.ndarray, w: np.ndarray,
                  rest: Sequence[tuple[float | None, float | None]] | None = None, min_rest: float = 0.3,
                  source: str = "", notes: Sequence[str] = (), method: str = "whittle") -> SensorFit:
    """Fit the noise model of a wrench recording.

    Args:
        t: Times [s] (increasing).
        w: (N, 6) fx fy fz tx ty tz.
        rest: Rest windows (t0, t1) [s] (None: the recording's start / end; negative: from the end). The
            first is fitted; with two or more, the offset change is from the first to the last. Without
            them the windows are found by :func:`find_rest_windows` and the longest is fitted.
        min_rest: Shortest detected rest window [s].
        source: The recording's name (for the report).
        notes: Said in the report.
        method: ``whittle`` or ``acf`` (see :func:`fit_axis`).
    """
    t = np.asarray(t, dtype=float)
    w = np.asarray(w, dtype=float)
    if w.ndim != 2 or w.shape[1] != 6 or len(t) != len(w):
        raise SensorFitError(f"expected times (N,) and a wrench (N, 6), got {t.shape} and {w.shape}")
    if len(t) < MIN_SAMPLES:
        raise SensorFitError(f"{source or 'recording'}: too few samples ({len(t)} < {MIN_SAMPLES})")
    notes = list(notes)
    d = np.diff(t)
    dt = float(np.median(d))
    if dt <= 0:
        raise SensorFitError(f"{source or 'recording'}: the median sample interval is {dt} s")
    gaps = [Gap(float(t[i]), float(d[i])) for i in np.flatnonzero(d > GAP_FACTOR * dt)]
    if rest:
        windows = [given_window(t, w, a, b) for a, b in rest]
        fit_window = windows[0]
    else:
        holds: list[RestWindow] = []
        windows = find_rest_windows(t, w, min_rest, holds)
        for h in holds:
            notes.append(f"quiet {h.t0:.3f}-{h.t1:.3f} s left out: force away from the first and last rest "
                         f"offsets (a steady hold?), mean {' '.join(f'{v:.3g}' for v in h.mean[:3])} N")
        if not windows:
            raise SensorFitError(f"{source or 'recording'}: no rest window of {min_rest:g} s found "
                                 f"({REST_RULE}): give one with --rest T0:T1")
        fit_window = max(windows, key=lambda r: r.t1 - r.t0)
    i0 = int(np.searchsorted(t, fit_window.t0, "left"))
    i1 = i0 + fit_window.n
    inside = [g for g in gaps if fit_window.t0 <= g.time < fit_window.t1]
    if inside:
        notes.append(f"{len(inside)} gap(s) inside the fit window: lags counted in samples, not time")
    axes = [fit_axis(w[i0:i1, j], dt, AXES[j], UNITS[j], method) for j in range(6)]
    taus = [a.tau for a in axes[:3] if a.tau is not None]
    common_tau = float(np.median(taus)) if taus else None
    if common_tau is not None:
        tau = common_tau
        common = [tuple(math.sqrt(v) for v in _fit_fixed(w[i0:i1, j], dt, tau, method)) for j in range(6)]
    else:
        common = [(a.white, a.drift) for a in axes]
    jumps = []
    dw = np.diff(w, axis=0)
    for j in range(6):
        k = int(np.argmax(np.abs(dw[:, j])))
        jumps.append(Jump(AXES[j], UNITS[j], float(dw[k, j]), float(t[k + 1]), bool(d[k] > GAP_FACTOR * dt)))
    shift = None
    contact = False
    ordered = sorted(windows, key=lambda r: r.t0)
    if len(ordered) >= 2:
        first, last = ordered[0], ordered[-1]
        between = (t > first.t1) & (t < last.t0)
        if between.any():
            rel = w[between, :3] - np.asarray(first.mean[:3])
            mag = np.linalg.norm(rel, axis=1)
            k = int(np.argmax(mag))
            change = tuple(b - a for a, b in zip(first.mean, last.mean, strict=True))
            shift = ContactShift(first, last, change, float(mag[k]),
                                 (float(rel[k, 0]), float(rel[k, 1]), float(rel[k, 2])), float(t[between][k]))
            noise = max(a.std for a in axes[:3])
            contact = shift.peak > CONTACT_FACTOR * noise
    return SensorFit(source=source, n=len(t), duration=float(t[-1] - t[0]), dt_median=dt,
                     dt_std=float(d.std()), dt_min=float(d.min()), dt_max=float(d.max()), gaps=gaps,
                     rest_windows=windows, fit_window=fit_window, axes=axes, jumps=jumps, shift=shift,
                     contact=contact, common_tau=common_tau, common=common, min_rest=min_rest, method=method,
                     notes=notes)
