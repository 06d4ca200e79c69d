"""First-order low-pass filter of joint velocity commands, unit DC gain, initialised from the current state.

The filter is ``y_k = (x_k + x_{k-1} - (1 - c) y_{k-1}) / (1 + c)``: the bilinear transform of a first-order
lag (time constant about ``c / 2`` cycles), the family of the fork's filter. The fork's version had a DC gain
of 4/3 (a constant command came out a third too fast) and started from zero state, so its first outputs
after start-up were wrong (the thesis added a stabilization period). Here the gain is exactly 1 and
:meth:`reset` loads the current value into both memories, so the first output after a (re)start equals the
state it starts from.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["LowPassFilter"]


class LowPassFilter:
    """Vector low-pass filter ``y_k = (x_k + x_{k-1} - (1 - c) y_{k-1}) / (1 + c)``.

    The pole is ``(c - 1) / (c + 1)``, in [0, 1) for ``c >= 1`` (no ringing); ``c = 1`` passes the mean of the
    last two inputs. Works on plain float lists: for 6 or 7 joints that beats numpy's per-call overhead.

    Args:
        coeff: The fork's `low_pass_filter_coeff` c (>= 1; larger smooths more).
        size: Vector length.

    Raises:
        ValueError: ``coeff < 1``.
    """

    def __init__(self, coeff: float, size: int) -> None:
        self.set_coeff(coeff)
        self._size = size
        self._x_prev = [0.0] * size
        self._y_prev = [0.0] * size

    def set_coeff(self, coeff: float) -> None:
        """A new c, continuing from the filter's memories (live tuning: no jump in its output)."""
        if not coeff >= 1.0:
            raise ValueError(f"low_pass_filter_coeff must be >= 1, got {coeff}")
        self._gain = 1.0 / (1.0 + coeff)
        self._feedback = 1.0 - coeff

    def reset(self, value: Sequence[float] | float = 0.0) -> None:
        """Starts from steady state at `value` (both memories), so the next output has no jump."""
        values = [float(value)] * self._size if isinstance(value, int | float) else [float(v) for v in value]
        if len(values) != self._size:
            raise ValueError(f"filter state needs {self._size} values, got {len(values)}")
        self._x_prev = values
        self._y_prev = list(values)

    def filter(self, x: Sequence[float]) -> list[float]:
        """Filters one sample (a sequence of floats; pass ``array.tolist()`` for numpy input).

        Returns:
            The filtered sample, a new list.
        """
        gain = self._gain
        feedback = self._feedback
        y = [
            gain * (xi + xp - feedback * yp) for xi, xp, yp in zip(x, self._x_prev, self._y_prev, strict=True)
        ]
        self._x_prev = list(x)
        self._y_prev = y
        return y
