"""Publishing the mission to late joiners and the agents' state at a steady rate.

:class:`SnapshotPublisher` publishes the full mission latched on
``/rosmc/mission`` (rosmc/Mission). Under a burst of changes it coalesces:
it waits until changes pause (``quiet``) or a burst has lasted ``max_delay``,
so a multi-megabyte snapshot is not built per change, yet the latched
snapshot is always current shortly after a burst ends. The snapshot is for late joiners,
not a stream (clients follow ``/rosmc/mission_events``): after one is published the next
waits at least ``min_period``, and during a long burst at least ``cost_factor`` times
what the last one cost, so building and serializing a large mission takes a bounded share
of the server's time (the service threads share one interpreter with it). A replaced
mission (new or loaded) is published at once: its content is only in the snapshot.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import rosmc.msg as wire
import rospy

_log = logging.getLogger(__name__)


class SnapshotPublisher:
    """Coalescing publisher of the latched mission snapshot."""

    def __init__(
        self,
        topic: str,
        build: Callable[[], wire.Mission],
        quiet: float = 0.05,
        max_delay: float = 0.25,
        cost_factor: float = 20.0,
        min_period: float = 0.5,
        on_published: Callable[[wire.Mission], None] | None = None,
    ) -> None:
        self._publisher = rospy.Publisher(topic, wire.Mission, queue_size=1, latch=True)
        self._build = build
        self._on_published = on_published
        self._quiet = quiet
        self._max_delay = max_delay
        self._cost_factor = cost_factor
        self._min_period = min_period
        self._published = 0.0  # monotonic time of the last publish
        self._urgent = False
        self._cost = 0.0  # seconds the last snapshot took to build and publish
        self._changed = threading.Condition()
        self._dirty_since: float | None = None
        self._last_change = 0.0
        self._stopped = False
        self._thread = threading.Thread(target=self._run, name="snapshot", daemon=True)

    def start(self) -> None:
        """Publish the first snapshot now and start following changes."""
        self._publisher.publish(self._build())
        self._thread.start()

    def changed(self, urgent: bool = False) -> None:
        """The mission changed; a new snapshot will follow (``urgent``: as soon as it can)."""
        with self._changed:
            now = time.monotonic()
            self._urgent = self._urgent or urgent
            self._last_change = now
            if self._dirty_since is None:
                self._dirty_since = now
            self._changed.notify()

    def stop(self) -> None:
        """Stop the publishing thread."""
        with self._changed:
            self._stopped = True
            self._changed.notify()
        if self._thread.is_alive():
            self._thread.join(timeout=2.0)

    def _run(self) -> None:
        while True:
            with self._changed:
                while self._dirty_since is None and not self._stopped:
                    self._changed.wait()
                if self._stopped:
                    return
                self._wait_for_pause()
                self._dirty_since, self._urgent = None, False
            started = time.monotonic()
            try:
                snapshot = self._build()
                self._publisher.publish(snapshot)
                if self._on_published is not None:
                    self._on_published(snapshot)
            except Exception:  # keep publishing later snapshots whatever happened
                _log.exception("could not publish the mission snapshot")
            self._published = time.monotonic()
            self._cost = self._published - started

    def _wait_for_pause(self) -> None:
        """Wait (lock held) until changes pause or the burst is old enough."""
        assert self._dirty_since is not None
        while not self._stopped:
            now = time.monotonic()
            longest = max(self._max_delay, self._cost_factor * self._cost)
            deadline = min(self._last_change + self._quiet, self._dirty_since + longest)
            if not self._urgent:
                spacing = max(self._min_period, self._cost_factor * self._cost)
                deadline = max(deadline, self._published + spacing)
            if now >= deadline:
                return
            self._changed.wait(deadline - now)
