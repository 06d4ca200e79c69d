"""ROS1 bags for tests: written and read with `rosbags`, replayed into live topics with rospy."""

from __future__ import annotations

import functools
import pathlib
import time
from collections.abc import Iterable, Sequence
from typing import Any

from rosbags.rosbag1 import Reader, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

__all__ = ["read_bag", "replay_bag", "typestore", "write_bag"]

_SRC = pathlib.Path(__file__).resolve().parents[2] / "src"


@functools.cache
def typestore():
    """The ROS1 Noetic type store plus this workspace's own messages."""
    store = get_typestore(Stores.ROS1_NOETIC)
    types: dict = {}
    for msg_file in sorted(_SRC.glob("**/msg/*.msg")):
        package = msg_file.parent.parent.name
        types.update(get_types_from_msg(msg_file.read_text(), f"{package}/msg/{msg_file.stem}"))
    store.register(types)
    return store


def write_bag(path: str | pathlib.Path, messages: Iterable[tuple[str, str, int, Any]]) -> None:
    """Writes (topic, msgtype, stamp_ns, message) tuples to a ROS1 bag at `path`."""
    store = typestore()
    connections: dict[tuple[str, str], Any] = {}
    with Writer(pathlib.Path(path)) as writer:
        for topic, msgtype, stamp_ns, msg in messages:
            key = (topic, msgtype)
            if key not in connections:
                connections[key] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(connections[key], stamp_ns, store.serialize_ros1(msg, msgtype))


def read_bag(path: str | pathlib.Path, topics: Sequence[str] | None = None) -> list[tuple[str, int, Any]]:
    """Reads a ROS1 bag (only ``topics`` if given) into (topic, stamp_ns, message) tuples in time order."""
    store = typestore()
    with Reader(pathlib.Path(path)) as reader:
        connections = [c for c in reader.connections if topics is None or c.topic in topics]
        return [
            (conn.topic, stamp, store.deserialize_ros1(raw, conn.msgtype))
            for conn, stamp, raw in reader.messages(connections=connections)
        ]


def replay_bag(
    path: str | pathlib.Path, rate: float = 1.0, restamp: bool = True, latch_wait: float = 5.0
) -> int:
    """Publishes a bag's messages with rospy, keeping their recorded spacing.

    Args:
        path: the bag.
        rate: playback speed factor.
        restamp: set header stamps to now, so receivers see fresh data.
        latch_wait: seconds to wait for each topic's first subscriber before playing.

    Returns:
        The number of messages published.
    """
    import rospy
    from roslib.message import get_message_class

    with Reader(pathlib.Path(path)) as reader:
        entries = [(conn.topic, conn.msgtype, stamp, bytes(raw)) for conn, stamp, raw in reader.messages()]
    publishers: dict[str, tuple[Any, type]] = {}
    for topic, msgtype, _, _ in entries:
        if topic not in publishers:
            cls = get_message_class(msgtype.replace("/msg/", "/"))
            publishers[topic] = (rospy.Publisher(topic, cls, queue_size=100, tcp_nodelay=True), cls)
    deadline = time.monotonic() + latch_wait
    while time.monotonic() < deadline and any(p.get_num_connections() == 0 for p, _ in publishers.values()):
        time.sleep(0.01)
    if not entries:
        return 0
    start_wall = time.monotonic()
    start_bag = entries[0][2]
    for topic, _, stamp, raw in entries:
        due = start_wall + (stamp - start_bag) / 1e9 / rate
        pause = due - time.monotonic()
        if pause > 0:
            time.sleep(pause)
        pub, cls = publishers[topic]
        msg = cls().deserialize(raw)
        if restamp and hasattr(msg, "header"):
            msg.header.stamp = rospy.Time.now()
        pub.publish(msg)
    return len(entries)
