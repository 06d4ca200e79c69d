"""The message when a path server gives no answer names where it hung."""

from __future__ import annotations

from thesis_demos.path_silence import silence_words


def test_the_last_feedback_is_named_with_its_age():
    words = silence_words((100.0, "touch", 0.0, 2.25), 112.5)
    assert words == "its last feedback 12.5 s before: step touch, progress 0.00, force 2.2 N"


def test_no_feedback_is_said():
    assert silence_words(None, 5.0) == "no feedback came"
