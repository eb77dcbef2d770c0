"""Follow a latched topic for clients: the newest message, converted to a core value.

The science state (:mod:`.science`) and the site map in force (:mod:`.site`) are both
latched topics a client reads once (``rosmc status``) or follows (the command GUI).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any, Generic, TypeVar

import rosgraph
import rospy

T = TypeVar("T")


class LatchedWatch(Generic[T]):
    """Follows ``topic``; ``on_value`` (if given) hears each converted message on a ROS thread.

    The process must be a ROS node already.
    """

    def __init__(
        self,
        topic: str,
        msg_class: Any,
        convert: Callable[[Any], T],
        on_value: Callable[[T], None] | None = None,
    ) -> None:
        self.topic = topic
        self._convert = convert
        self._on_value = on_value
        self._latest: T | None = None
        self._arrived = threading.Event()
        self._subscriber = rospy.Subscriber(topic, msg_class, self._on_message)

    @property
    def latest(self) -> T | None:
        """The newest value, None before the first."""
        return self._latest

    def published(self) -> bool:
        """Someone publishes the topic now (the master says so)."""
        master = rosgraph.Master(rospy.get_name())
        publishers = master.getSystemState()[0]
        return any(topic == self.topic and nodes for topic, nodes in publishers)

    def wait(self, timeout: float) -> T | None:
        """The value, waiting up to ``timeout`` s if the topic is published; else None."""
        if self._latest is None and self.published():
            self._arrived.wait(timeout)
        return self._latest

    def close(self) -> None:
        """Stop following."""
        self._subscriber.unregister()

    def _on_message(self, msg: Any) -> None:
        value = self._convert(msg)
        self._latest = value
        self._arrived.set()
        if self._on_value is not None:
            self._on_value(value)
