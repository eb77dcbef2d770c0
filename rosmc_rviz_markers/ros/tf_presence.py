"""Which agents' TF frames are there: the marker node draws the others in the map frame.

rviz's interactive-marker display holds back a whole update until it can transform every
marker in it, so one agent whose ``<agent>/base_link`` is missing (a robot not started
yet, or powered off) kept every robot from being drawn. The node asks this watcher and
places such an agent in the map frame instead (see :class:`~..core.scene.Scene`).

Subscribes ``/tf`` and ``/tf_static`` (through a ``tf2_ros.TransformListener``).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

import rospy
import tf2_ros

from rosmc_server.interface import MAP_FRAME, base_link

_log = logging.getLogger(__name__)

FIRST_LOOK = 2.0
"""Seconds before the first look: the frames of a running simulator arrive by then."""


class TfPresence:
    """Calls ``on_change`` with the agents whose frame cannot be transformed to the map.

    Looks every ``period`` seconds (after :data:`FIRST_LOOK`), on its own thread, and
    calls only when the set changed.

    Args:
        agents: Returns the agents to look for (the library may change).
        on_change: Called with the agents whose frame is missing.
        period: Seconds between looks.
    """

    def __init__(
        self,
        agents: Callable[[], list[str]],
        on_change: Callable[[frozenset[str]], None],
        period: float = 1.0,
    ) -> None:
        self._agents = agents
        self._on_change = on_change
        self._period = period
        self._buffer = tf2_ros.Buffer()
        self._listener = tf2_ros.TransformListener(self._buffer)
        self._missing: frozenset[str] = frozenset()
        self._closed = threading.Event()
        self._thread = threading.Thread(target=self._run, name="rosmc-tf-presence", daemon=True)
        self._thread.start()

    @property
    def last(self) -> frozenset[str]:
        """The agents whose frame was missing at the last look."""
        return self._missing

    def missing(self) -> frozenset[str]:
        """The agents whose frame is missing now."""
        frames = {agent: base_link(agent) for agent in self._agents()}
        latest = rospy.Time(0)
        return frozenset(
            agent
            for agent, frame in frames.items()
            if not self._buffer.can_transform(MAP_FRAME, frame, latest)
        )

    def close(self) -> None:
        """Stop looking."""
        self._closed.set()
        self._listener.unregister()

    def _run(self) -> None:
        if self._closed.wait(FIRST_LOOK):
            return
        while True:
            try:
                missing = self.missing()
                if missing != self._missing:
                    self._missing = missing
                    _log.info("agents without TF: %s", ", ".join(sorted(missing)) or "none")
                    self._on_change(missing)
            except Exception:  # a bad look must not stop the looking for good
                _log.exception("cannot look up the agents' TF frames")
            if self._closed.wait(self._period):
                return
