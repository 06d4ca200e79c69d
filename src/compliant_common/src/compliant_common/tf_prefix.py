"""A robot's tf prefix (README, *Namespaces*): its links are `<prefix>/<link>` on /tf, while its
description, its YAML files and every computation inside a node keep the bare names. Nodes add the prefix
to the frames they publish or look up, and take it off the frames they receive."""

from __future__ import annotations

__all__ = ["TfPrefix"]


class TfPrefix:
    """`TfPrefix("left")`: add("base_link") is "left/base_link", bare("left/base_link") is "base_link".
    An empty prefix changes nothing but a leading "/" (tf2 names have none)."""

    __slots__ = ("_head",)

    def __init__(self, prefix: str = "") -> None:
        prefix = prefix.strip("/")
        if any(c.isspace() for c in prefix):
            raise ValueError(f"tf_prefix {prefix!r}: a tf frame prefix has no spaces")
        self._head = prefix + "/" if prefix else ""

    @property
    def prefix(self) -> str:
        """The prefix without slashes ('' for none)."""
        return self._head[:-1]

    def add(self, frame: str) -> str:
        """The tf name of this robot's `frame` ('' stays '': a message's "no frame")."""
        frame = frame.lstrip("/")
        if not frame or not self._head or frame.startswith(self._head):
            return frame
        return self._head + frame

    def bare(self, frame: str) -> str:
        """The bare name of a frame received from tf or a message (a frame without the prefix is taken as
        bare already)."""
        frame = frame.lstrip("/")
        if self._head and frame.startswith(self._head):
            return frame[len(self._head):]
        return frame

    def __bool__(self) -> bool:
        return bool(self._head)

    def __repr__(self) -> str:
        return f"TfPrefix({self.prefix!r})"

