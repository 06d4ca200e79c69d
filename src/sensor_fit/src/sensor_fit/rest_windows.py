"""Where the sensor is at rest: found in the data, or given.

Rest windows (when none are given), :data:`REST_RULE`: the centred moving standard deviation of each force
axis over ``max(0.2 s, 30 samples)``; the axis's reference is the 5th percentile of that moving std over
the whole recording (the noise of its quietest stretches); a sample is at rest when the moving std of every
force axis is at most 3 times its reference; rest windows are the runs of such samples at least
``min_rest`` (0.3 s) and 20 samples long, split at gaps. A quiet run between the first and the last whose
mean force is more than 10 references (the largest force axis's) away from both theirs is a steady hold
(a constant push), not rest, and is left out (listed in the report). This needs at least ~5 % of the
recording at rest, and it takes the first and the last quiet runs for rest: give the windows (``--rest``)
when the recording starts or ends in a hold.
"""

from __future__ import annotations

import itertools

import numpy as np

from sensor_fit.errors import SensorFitError
from sensor_fit.recordings import MIN_SAMPLES
from sensor_fit.results import GAP_FACTOR, RestWindow

__all__ = ["REST_RULE", "find_rest_windows", "given_window"]

REST_WINDOW_S = 0.2         # moving-std window of the rest detection [s] ...
REST_WINDOW_MIN = 30        # ... and at least this many samples
REST_PERCENTILE = 5.0       # the reference noise: this percentile of the moving std
REST_FACTOR = 3.0           # at rest: moving std <= this times the reference, on every force axis
HOLD_FACTOR = 10.0          # a quiet run this many reference stds from the first and last is a hold
REST_RULE = (f"moving std over max({REST_WINDOW_S:g} s, {REST_WINDOW_MIN} samples) <= {REST_FACTOR:g} x its "
             f"{REST_PERCENTILE:g}th percentile over the recording, on every force axis; in between the "
             f"first and the last, mean force within {HOLD_FACTOR:g} x that percentile of either")


def _moving_std(x: np.ndarray, w: int) -> np.ndarray:
    """Centred moving std over w samples (edges: the nearest full window)."""
    n = len(x)
    if n <= w:
        return np.full(n, float(np.std(x)))
    y = x - np.median(x)
    c1 = np.concatenate([[0.0], np.cumsum(y)])
    c2 = np.concatenate([[0.0], np.cumsum(y * y)])
    s1 = c1[w:] - c1[:-w]
    s2 = c2[w:] - c2[:-w]
    std = np.sqrt(np.maximum(s2 / w - (s1 / w) ** 2, 0.0))   # len n - w + 1, window starting at i
    start = np.clip(np.arange(n) - w // 2, 0, n - w)
    return std[start]


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) index runs of True."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True))


def _window(t: np.ndarray, w: np.ndarray, i0: int, i1: int, given: bool = False) -> RestWindow:
    return RestWindow(float(t[i0]), float(t[i1 - 1]), i1 - i0, tuple(float(v) for v in w[i0:i1].mean(axis=0)),
                      given)


def find_rest_windows(t: np.ndarray, w: np.ndarray, min_rest: float = 0.3,
                      holds: list[RestWindow] | None = None) -> list[RestWindow]:
    """Rest windows by :data:`REST_RULE` (module docstring), in time order; the quiet stretches left out as
    holds are appended to ``holds``."""
    dt = float(np.median(np.diff(t)))
    width = max(REST_WINDOW_MIN, round(REST_WINDOW_S / dt))
    s = np.column_stack([_moving_std(w[:, i], width) for i in range(3)])
    ref = np.percentile(s, REST_PERCENTILE, axis=0)
    ref = np.maximum(ref, 1e-9 * max(1.0, float(np.abs(w[:, :3]).max())))
    quiet = np.all(s <= REST_FACTOR * ref, axis=1)
    breaks = np.flatnonzero(np.diff(t) > GAP_FACTOR * dt) + 1   # a gap ends a window
    windows = []
    for start, stop in _runs(quiet):
        bounds = [start, *[int(b) for b in breaks if start < b < stop], stop]
        for i0, i1 in itertools.pairwise(bounds):
            if i1 - i0 >= MIN_SAMPLES and t[i1 - 1] - t[i0] >= min_rest:
                windows.append(_window(t, w, i0, i1))
    if len(windows) <= 2:
        return windows
    # A quiet stretch between them whose force is far from both the first and the last window's is a hold.
    tol = HOLD_FACTOR * float(ref.max())
    ends = [np.asarray(windows[0].mean[:3]), np.asarray(windows[-1].mean[:3])]
    kept = [windows[0]]
    for win in windows[1:-1]:
        if min(float(np.linalg.norm(np.asarray(win.mean[:3]) - e)) for e in ends) <= tol:
            kept.append(win)
        elif holds is not None:
            holds.append(win)
    return [*kept, windows[-1]]


def given_window(t: np.ndarray, w: np.ndarray, t0: float | None, t1: float | None) -> RestWindow:
    """The rest window [t0, t1] [s] given by hand (None: the recording's start / end; negative: from its end),
    at least :data:`~sensor_fit.recordings.MIN_SAMPLES` long."""
    end = float(t[-1])
    a = 0.0 if t0 is None else (end + t0 if t0 < 0 else t0)
    b = end if t1 is None else (end + t1 if t1 < 0 else t1)
    i0, i1 = int(np.searchsorted(t, a, "left")), int(np.searchsorted(t, b, "right"))
    if i1 - i0 < MIN_SAMPLES:
        raise SensorFitError(f"rest window {a:.3f}-{b:.3f} s: too few samples ({max(i1 - i0, 0)} < "
                             f"{MIN_SAMPLES}; the recording spans 0-{end:.3f} s)")
    return _window(t, w, i0, i1, given=True)

