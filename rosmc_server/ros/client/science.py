"""What the science team (the simulator) publishes, for clients: the score and the regions.

Subscribes ``/rosmc/sim/science`` (rosmc/ScienceState, latched; behind a replay's prefix
when given).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

import rosgraph
import rosmc.msg as wire
import rospy

from ... import interface
from ...conversions.science import science_from_msg
from ...core.science import Science

SCIENCE_TYPE = "rosmc/ScienceState"


class ScienceWatch:
    """Follows the science state; ``on_science`` (if given) hears each one on a ROS thread.

    The process must be a ROS node already.
    """

    def __init__(
        self, prefix: str = "", on_science: Callable[[Science], None] | None = None
    ) -> None:
        self.topic = interface.prefixed(interface.SCIENCE_TOPIC, prefix)
        self._on_science = on_science
        self._latest: Science | None = None
        self._arrived = threading.Event()
        self._subscriber = rospy.Subscriber(self.topic, wire.ScienceState, self._on_message)

    @property
    def latest(self) -> Science | None:
        """The newest science state, None before the first."""
        return self._latest

    def published(self) -> bool:
        """Someone publishes the topic now (the master says so)."""
        master = rosgraph.Master(rospy.get_name())
        publishers = master.getSystemState()[0]
        return any(topic == self.topic and nodes for topic, nodes in publishers)

    def wait(self, timeout: float) -> Science | None:
        """The science state, waiting up to ``timeout`` s if it is published; else None."""
        if self._latest is None and self.published():
            self._arrived.wait(timeout)
        return self._latest

    def close(self) -> None:
        """Stop following."""
        self._subscriber.unregister()

    def _on_message(self, msg: wire.ScienceState) -> None:
        self._latest = science_from_msg(msg)
        self._arrived.set()
        if self._on_science is not None:
            self._on_science(self._latest)
