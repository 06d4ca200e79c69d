"""What a path server said last, for the message when it gives no answer in time (a hung step is named)."""

from __future__ import annotations

__all__ = ["silence_words"]


def silence_words(last: tuple[float, str, float, float] | None, now: float) -> str:
    """`last`: (stamp [s], step, progress 0..1, force [N]) of its last feedback, None if none came."""
    if last is None:
        return "no feedback came"
    at, step, progress, force = last
    return (f"its last feedback {now - at:.1f} s before: step {step}, progress {progress:.2f}, "
            f"force {force:.1f} N")
