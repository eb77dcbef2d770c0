"""Publishing the mission to late joiners and the agents' state at a steady rate.

:class:`SnapshotPublisher` gives the full mission (rosmc/Mission) on ``/rosmc/mission`` to
each subscriber as it connects, as a latched topic does, but it is current: the newest
snapshot built, not the one last broadcast. A change is not broadcast to the subscribers
already there: they follow ``/rosmc/mission_events``, and a snapshot to each of them per
change would cost every change the whole mission on the wire (megabytes at 10,000 skills).
Only a replaced mission (new or loaded), whose content is in no event, goes to everyone.

Snapshots are still built after changes, for the journal's periodic snapshot
(``on_built``) and for the next subscriber, coalesced: after a change it waits until
changes pause (``quiet``) or a burst has lasted ``max_delay``; the next waits at least
``min_period``, and during a long burst at least ``cost_factor`` times what the last one
cost, so building a large mission takes a bounded share of the server's time (the service
threads share one interpreter with it). A subscriber that connects meanwhile gets the
mission of the current revision, built then (the build is cached per revision).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import rosmc.msg as wire
import rospy

_log = logging.getLogger(__name__)


class SnapshotPublisher(rospy.SubscribeListener):  # type: ignore[misc]
    """The mission snapshot for each new subscriber, and the coalesced builds after changes.

    Args:
        topic: Where to publish.
        build: The snapshot of the current revision (cached by the caller per revision).
        on_built: Called with each snapshot built after changes (on the builder thread).
        broadcast_changes: Send every coalesced snapshot to every subscriber too (the
            behaviour before per-subscriber snapshots; benchmarks compare the two).
    """

    def __init__(
        self,
        topic: str,
        build: Callable[[], wire.Mission],
        quiet: float = 0.05,
        max_delay: float = 0.25,
        cost_factor: float = 20.0,
        min_period: float = 0.5,
        on_built: Callable[[wire.Mission], None] | None = None,
        broadcast_changes: bool = False,
    ) -> None:
        super().__init__()
        # Not latched: rospy would send a new subscriber the last broadcast, which is stale
        # once changes are no longer broadcast; peer_subscribe sends the current one instead.
        self._publisher = rospy.Publisher(
            topic, wire.Mission, subscriber_listener=self, queue_size=1
        )
        self._sending = threading.Lock()  # one snapshot on the wire at a time, in order
        self._build = build
        self._on_built = on_built
        self._broadcast_changes = broadcast_changes
        self._quiet = quiet
        self._max_delay = max_delay
        self._cost_factor = cost_factor
        self._min_period = min_period
        self._published = 0.0  # monotonic time of the last publish
        self._urgent = False
        self._cost = 0.0  # seconds the last snapshot took to build and publish
        self._changed = threading.Condition()
        self._dirty_since: float | None = None
        self._building = False  # a snapshot is being built and sent
        self._last_change = 0.0
        self._stopped = False
        self._thread = threading.Thread(target=self._run, name="snapshot", daemon=True)

    def start(self) -> None:
        """Start following changes (subscribers get the mission as they connect)."""
        self._thread.start()

    def peer_subscribe(
        self, topic_name: str, topic_publish: Callable[..., None], peer_publish: Callable[..., None]
    ) -> None:
        """A subscriber connected: send it the current snapshot (rospy's connection thread)."""
        try:
            with self._sending:
                peer_publish(self._build())
        except Exception:  # one subscriber's failure must not break rospy's accept thread
            _log.exception("could not send the mission snapshot to a new subscriber")

    def changed(self, urgent: bool = False) -> None:
        """The mission changed; a new snapshot will be built (``urgent``: as soon as it can,
        and sent to every subscriber: the mission was replaced)."""
        with self._changed:
            now = time.monotonic()
            self._urgent = self._urgent or urgent
            self._last_change = now
            if self._dirty_since is None:
                self._dirty_since = now
            self._changed.notify()

    @property
    def idle(self) -> bool:
        """Whether no snapshot waits to be built or is being built."""
        with self._changed:
            return self._dirty_since is None and not self._building

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
                broadcast = self._urgent or self._broadcast_changes
                self._dirty_since, self._urgent = None, False
                self._building = True
            started = time.monotonic()
            self._build_and_publish(broadcast)
            with self._changed:
                self._building = False
            self._published = time.monotonic()
            self._cost = self._published - started

    def _build_and_publish(self, broadcast: bool) -> None:
        """Build the snapshot, publish it if ``broadcast``, hand it to ``on_built``.

        Not kept afterwards (megabytes): the next one is built from the mission.
        """
        try:
            with self._sending:
                snapshot = self._build()
                if broadcast:
                    self._publisher.publish(snapshot)
            if self._on_built is not None:
                self._on_built(snapshot)
        except Exception:  # keep building later snapshots whatever happened
            _log.exception("could not build or publish the mission snapshot")

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
